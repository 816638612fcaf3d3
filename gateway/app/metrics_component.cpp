#include "app/metrics_component.hpp"

#include <exception>
#include <utility>

namespace fieldbridge::app {

MetricsComponent::MetricsComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, std::string version)
    : io_(io), logger_(std::move(logger)), version_(std::move(version)) {}

MetricsComponent::~MetricsComponent() = default;

void MetricsComponent::add_collector(Collector collector) {
    collectors_.push_back(std::move(collector));
}

void MetricsComponent::start(daemon::StartContext& context) {
    const auto& config = context.config()->metrics_http;
    if (!config) {
        logger_->debug("metrics HTTP endpoint off (no metrics_http section)");
        return;
    }
    auto ready = context.expect_ready("metrics HTTP listener " + config->listen.to_string());
    open(config->listen);  // throws metrics::MetricsHttpError: the daemon exits 1 with its message
    ready.done();
}

void MetricsComponent::stop(daemon::StopContext& /*context*/) {
    prepared_.reset();
    endpoint_.reset();
}

void MetricsComponent::prepare(const config::Config& next) {
    prepared_.reset();
    const auto& wanted = next.metrics_http;
    if (!wanted || (endpoint_ && endpoint_->address() == wanted->listen)) return;
    try {
        prepared_ = std::make_unique<metrics::HttpEndpoint>(io_, wanted->listen, [this] { return render(); });
    } catch (const metrics::MetricsHttpError&) {
        // Our own endpoint may hold the port (0.0.0.0 -> 127.0.0.1): apply() binds
        // once it closed. Any other holder rejects the reload.
        if (!endpoint_ || endpoint_->address().port != wanted->listen.port) throw;
    }
}

void MetricsComponent::abandon() noexcept { prepared_.reset(); }

void MetricsComponent::apply(std::shared_ptr<const config::Config> config) {
    const auto& wanted = config->metrics_http;
    if (!wanted) {
        prepared_.reset();
        if (endpoint_) logger_->info("metrics HTTP endpoint closed (metrics_http removed)");
        endpoint_.reset();
        return;
    }
    if (endpoint_ && endpoint_->address() == wanted->listen) return;
    if (prepared_) {
        endpoint_ = std::move(prepared_);
        announce(*endpoint_);
        return;
    }
    try {
        open(wanted->listen);
    } catch (const metrics::MetricsHttpError&) {
        if (!endpoint_) throw;
        // The new address may overlap the old one (0.0.0.0 -> 127.0.0.1, same port):
        // free the old listener and try once more.
        endpoint_.reset();
        open(wanted->listen);
    }
}

void MetricsComponent::announce(const metrics::HttpEndpoint& endpoint) {
    const auto& address = endpoint.address();
    logger_->info("metrics HTTP endpoint: http://{}:{}/metrics", address.is_ipv6() ? "[" + address.host + "]"
                                                                                    : address.host,
                  endpoint.port());
}

void MetricsComponent::open(const config::ListenAddress& address) {
    auto endpoint = std::make_unique<metrics::HttpEndpoint>(io_, address, [this] { return render(); });
    announce(*endpoint);
    endpoint_ = std::move(endpoint);
}

std::string MetricsComponent::render() {
    ++scrapes_;
    metrics::MetricSet set;
    set.add_gauge("fieldbridge_build_info", "The running fieldbridge's version (always 1)", {{"version", version_}},
                  1);
    set.add_counter("fieldbridge_metrics_scrapes_total", "Scrapes of this endpoint, this one included", {},
                    static_cast<double>(scrapes_));
    for (const auto& collect : collectors_) collect(set);
    return set.render();
}

}  // namespace fieldbridge::app
