#pragma once
/// @file metrics_component.hpp
/// The Prometheus endpoint as a daemon component: off when the configuration has
/// no `metrics_http` section. What a scrape shows comes from collectors that
/// gateway/app/main.cpp registers (the line engine, Modbus TCP, upstreams, MQTT,
/// reloads), each asked at scrape time on the loop thread: nothing is cached between
/// scrapes, so a rebuilt engine is simply what the next scrape walks.
///
/// READY waits for the listener. A reload rebinds only when `metrics_http.listen`
/// changed.
// Standard headers before asio's (see daemon/daemon.hpp).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <spdlog/logger.h>
#include <string>
#include <vector>

#include <asio/io_context.hpp>

#include "daemon/component.hpp"
#include "northbound/metrics/exposition.hpp"
#include "northbound/metrics/http_endpoint.hpp"

namespace fieldbridge::app {

namespace metrics = northbound::metrics;

class MetricsComponent final : public daemon::Component {
public:
    /// Adds the samples of one part of the gateway to a scrape.
    using Collector = std::function<void(metrics::MetricSet&)>;

    /// @p version is what `fieldbridge_build_info{version=...}` shows.
    MetricsComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, std::string version);
    ~MetricsComponent() override;

    [[nodiscard]] std::string name() const override { return "metrics HTTP endpoint"; }
    void start(daemon::StartContext& context) override;
    void stop(daemon::StopContext& context) override;
    /// A new metrics_http.listen is bound here: a reload whose address cannot be
    /// bound is rejected as a whole (unless the port is the one this endpoint frees).
    void prepare(const config::Config& next) override;
    void abandon() noexcept override;
    void apply(std::shared_ptr<const config::Config> config) override;

    /// Asked at every scrape, in the order added. Before start().
    void add_collector(Collector collector);

    /// The text a scrape returns now (also what the endpoint serves).
    [[nodiscard]] std::string render();
    /// Nullptr while the endpoint is off.
    [[nodiscard]] const metrics::HttpEndpoint* endpoint() const noexcept { return endpoint_.get(); }

private:
    void open(const config::ListenAddress& address);
    void announce(const metrics::HttpEndpoint& endpoint);

    asio::io_context& io_;
    std::shared_ptr<spdlog::logger> logger_;
    std::string version_;
    std::vector<Collector> collectors_;
    std::unique_ptr<metrics::HttpEndpoint> endpoint_;
    std::unique_ptr<metrics::HttpEndpoint> prepared_;  ///< bound by prepare() for the next apply()
    std::uint64_t scrapes_ = 0;
};

}  // namespace fieldbridge::app
