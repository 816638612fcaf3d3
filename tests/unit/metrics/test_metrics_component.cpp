// The metrics component: off without metrics_http, READY waits for its listener, a
// reload rebinds only when the address changed, and a scrape asks every collector.
#include <doctest/doctest.h>

#include <memory>
#include <spdlog/logger.h>
#include <string>

#include <asio/io_context.hpp>

#include "app/metrics_component.hpp"
#include "daemon/completion_barrier.hpp"

namespace fieldbridge::northbound::metrics {
namespace {

using app::MetricsComponent;

[[nodiscard]] std::shared_ptr<const config::Config> with_metrics(std::optional<config::ListenAddress> listen) {
    auto config = std::make_shared<config::Config>();
    if (listen) config->metrics_http = config::MetricsHttpConfig{*listen};
    return config;
}

[[nodiscard]] std::shared_ptr<spdlog::logger> quiet_logger() {
    return std::make_shared<spdlog::logger>("metrics-test");  // no sinks
}

/// Starts @p component with metrics_http on @p listen (READY is not waited for).
void start_on(MetricsComponent& component, const config::ListenAddress& listen) {
    daemon::CompletionBarrier readiness([] {});
    daemon::StartContext context(with_metrics(listen), readiness);
    component.start(context);
}

TEST_CASE("without metrics_http nothing listens and READY does not wait") {
    asio::io_context io;
    MetricsComponent component(io, quiet_logger(), "1.2.3");
    bool ready = false;
    daemon::CompletionBarrier readiness([&ready] { ready = true; });
    daemon::StartContext context(with_metrics(std::nullopt), readiness);
    component.start(context);
    readiness.arm();
    CHECK(ready);
    CHECK(component.endpoint() == nullptr);
}

TEST_CASE("with metrics_http the listener is up before READY and a scrape asks every collector") {
    asio::io_context io;
    MetricsComponent component(io, quiet_logger(), "1.2.3");
    int asked = 0;
    component.add_collector([&asked](MetricSet& out) {
        ++asked;
        out.add_gauge("fb_test_gauge", "A collector's sample", {}, 5);
    });
    daemon::CompletionBarrier readiness([] {});
    daemon::StartContext context(with_metrics(config::ListenAddress{"127.0.0.1", 0}), readiness);
    component.start(context);
    readiness.arm();
    CHECK(readiness.complete());
    REQUIRE(component.endpoint() != nullptr);
    CHECK(component.endpoint()->port() != 0);
    const std::string text = component.render();
    CHECK(asked == 1);
    CHECK(text.find("fieldbridge_build_info{version=\"1.2.3\"} 1\n") != std::string::npos);
    CHECK(text.find("fieldbridge_metrics_scrapes_total 1\n") != std::string::npos);
    CHECK(text.find("fb_test_gauge 5\n") != std::string::npos);
    CHECK(component.render().find("fieldbridge_metrics_scrapes_total 2\n") != std::string::npos);
    daemon::CompletionBarrier finished([] {});
    daemon::StopContext stop(finished);
    component.stop(stop);
    CHECK(component.endpoint() == nullptr);
}

TEST_CASE("a reload rebinds only when the address changed, and closes when the section goes") {
    asio::io_context io;
    MetricsComponent component(io, quiet_logger(), "1.2.3");
    start_on(component, config::ListenAddress{"127.0.0.1", 0});
    const HttpEndpoint* first = component.endpoint();
    REQUIRE(first != nullptr);
    const std::uint16_t port = first->port();

    component.apply(with_metrics(config::ListenAddress{"127.0.0.1", 0}));  // unchanged
    CHECK(component.endpoint() == first);
    CHECK(component.endpoint()->port() == port);

    component.apply(with_metrics(config::ListenAddress{"127.0.0.2", 0}));  // moved
    REQUIRE(component.endpoint() != nullptr);
    CHECK(component.endpoint()->address().host == "127.0.0.2");

    component.apply(with_metrics(std::nullopt));  // removed
    CHECK(component.endpoint() == nullptr);
    component.apply(with_metrics(config::ListenAddress{"127.0.0.1", 0}));  // added back
    CHECK(component.endpoint() != nullptr);
}

TEST_CASE("reload, first phase: a new address in use rejects the reload; prepared, it is taken; abandoned, it goes") {
    asio::io_context io;
    MetricsComponent component(io, quiet_logger(), "1.2.3");
    start_on(component, config::ListenAddress{"127.0.0.1", 0});
    const HttpEndpoint* first = component.endpoint();
    REQUIRE(first != nullptr);

    MetricsComponent other(io, quiet_logger(), "1.2.3");
    start_on(other, config::ListenAddress{"127.0.0.2", 0});
    const config::ListenAddress busy{"127.0.0.2", other.endpoint()->port()};
    CHECK_THROWS_AS(component.prepare(*with_metrics(busy)), MetricsHttpError);
    CHECK(component.endpoint() == first);

    const config::ListenAddress moved{"127.0.0.3", 0};
    component.prepare(*with_metrics(moved));
    component.abandon();
    CHECK(component.endpoint() == first);
    component.prepare(*with_metrics(moved));
    component.apply(with_metrics(moved));
    REQUIRE(component.endpoint() != nullptr);
    CHECK(component.endpoint()->address() == moved);
}

}  // namespace
}  // namespace fieldbridge::northbound::metrics
