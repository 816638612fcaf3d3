// fieldbridge: the gateway's entry point. Parses the command line, creates the
// logger, loads the configuration, and hands everything to the Daemon.

#include <nlohmann/json.hpp>
#include <spdlog/sinks/stdout_sinks.h>
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <iostream>
#include <type_traits>
#include <variant>

#include "app/engine_component.hpp"
#include "app/metrics_component.hpp"
#include "app/modbus_tcp_component.hpp"
#include "app/mqtt_component.hpp"
#include "app/scan_command.hpp"
#include "app/sparkplug_component.hpp"
#include "config/config_loader.hpp"
#include "daemon/check_config.hpp"
#include "daemon/command_line.hpp"
#include "daemon/daemon.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/logging.hpp"
#include "daemon/systemd_service_manager.hpp"
#include "daemon/systemd_sockets.hpp"
#include "northbound/metrics/engine_metrics.hpp"
#include "northbound/metrics/modbus_tcp_metrics.hpp"
#include "northbound/metrics/mqtt_metrics.hpp"
#include "northbound/metrics/process_metrics.hpp"
#include "northbound/mqtt/r6_source.hpp"

#ifndef FIELDBRIDGE_VERSION
#error "FIELDBRIDGE_VERSION must be defined by the build (gateway/app/CMakeLists.txt)"
#endif

namespace {

using namespace fieldbridge;

[[nodiscard]] std::shared_ptr<const config::Config> load(const std::filesystem::path& file) {
    return config::load_config_file(file);
}

[[nodiscard]] int run_gateway(const daemon::RunCommand& command) {
    // systemd.exec(5): JOURNAL_STREAM names the journal stream stderr is connected to.
    const auto format = daemon::detect_log_format(std::getenv("JOURNAL_STREAM"), STDERR_FILENO);
    auto logger = daemon::make_logger("fieldbridge", std::make_shared<spdlog::sinks::stderr_sink_mt>(), format);
    logger->set_level(daemon::to_spdlog_level(command.log_level.value_or(config::LogLevel::info)));
    logger->info("fieldbridge {}", FIELDBRIDGE_VERSION);

    std::shared_ptr<const config::Config> initial;
    try {
        initial = load(command.config_file);
    } catch (const config::ConfigError& error) {
        for (const auto& diagnostic : error.diagnostics()) {
            logger->error("{}", diagnostic.to_string());
        }
        logger->error("cannot start: the configuration {} cannot be used ({}); fix it (fieldbridge --check-config {} "
                      "lists every problem) and start again",
                      command.config_file.string(),
                      daemon::count_of(error.diagnostics().size(), "problem", "problems"),
                      command.config_file.string());
        return daemon::exit_config_error;
    }

    // Socket activation: listeners passed by systemd replace binding (docs/service.md).
    std::vector<northbound::modbus_tcp::InheritedListener> inherited;
    try {
        inherited = daemon::match_passed_sockets(initial->modbus_tcp.listen, daemon::take_systemd_sockets());
    } catch (const daemon::SocketActivationError& error) {
        logger->error("cannot start: {}", error.what());
        return daemon::exit_config_error;
    }

    daemon::SystemdServiceManager manager(logger);
    daemon::DaemonOptions options;
    options.config_file = command.config_file;
    options.log_level_override = command.log_level;
    daemon::Daemon gateway(std::move(options), std::move(initial), load, manager, logger);
    // Components start in this order and stop in the reverse one.
    app::EngineComponent engine(gateway.context(), logger);
    gateway.add_component(engine);
    gateway.add_status([&engine] { return engine.status(); });
    app::ModbusTcpComponent modbus_tcp(gateway.context(), logger, engine, std::move(inherited));
    gateway.add_component(modbus_tcp);
    gateway.add_status([&modbus_tcp] { return modbus_tcp.status(); });
    // MQTT last among the components: stopped first, so `offline` goes out while the
    // lines still run.
    app::MqttComponent mqtt(gateway.context(), logger, [&engine] { return engine.engine(); });
    // The R6 units as device sources: one copy for the JSON bridge, one for the Sparkplug
    // node (each source has one listener), rebuilt when the upstream targets change.
    struct R6Sources {
        std::vector<const void*> targets;  ///< the upstream targets they were made for
        std::vector<std::shared_ptr<northbound::mqtt::DeviceSource>> all, json, sparkplug;
    } r6;
    const auto r6_detach = [&r6] {
        northbound::mqtt::detach_r6_sources(r6.all);
        r6 = R6Sources{};
    };
    const auto r6_ensure = [&] {
        std::vector<const void*> targets;
        for (const auto& upstream : modbus_tcp.upstreams()) targets.push_back(upstream.get());
        if (targets == r6.targets && !r6.all.empty()) return;
        r6_detach();
        r6.targets = std::move(targets);
        for (const auto& upstream : modbus_tcp.upstreams()) {
            auto made = northbound::mqtt::make_r6_sources(gateway.context(), *upstream, 2);
            const std::size_t half = made.size() / 2;
            r6.json.insert(r6.json.end(), made.begin(), made.begin() + static_cast<std::ptrdiff_t>(half));
            r6.sparkplug.insert(r6.sparkplug.end(), made.begin() + static_cast<std::ptrdiff_t>(half), made.end());
            r6.all.insert(r6.all.end(), made.begin(), made.end());
        }
    };
    mqtt.add_sources([&] {
        r6_ensure();
        return r6.json;
    });
    modbus_tcp.on_upstreams_closing(r6_detach);
    mqtt.add_diag([&modbus_tcp] {
        nlohmann::json diag = nlohmann::json::object();
        if (const auto* server = modbus_tcp.server()) {
            const auto& stats = server->stats();
            diag["modbus_tcp"] = {{"clients", stats.connections_open},
                                  {"accepted", stats.connections_accepted},
                                  {"refused", stats.refused_max_connections + stats.refused_not_allowed +
                                                  stats.refused_per_client},
                                  {"requests", stats.requests},
                                  {"exceptions", stats.exceptions_total()},
                                  {"denied", stats.denied},
                                  {"closed_malformed", stats.closed_malformed}};
        }
        return diag;
    });
    gateway.add_component(mqtt);
    gateway.add_status([&mqtt] { return mqtt.status(); });
    // The Sparkplug B edge node after MQTT: stopped first, its NDEATH out while the lines run.
    app::SparkplugComponent sparkplug(
        gateway.context(), logger, [&engine] { return engine.engine(); }, FIELDBRIDGE_VERSION,
        [&modbus_tcp, &mqtt](northbound::sparkplug_node::NodeSnapshot& snapshot) {
            const std::string status = mqtt.status();
            snapshot.json_bridge = status == "MQTT connected" ? "connected" : status == "MQTT off" ? "off" : "connecting";
            for (const auto& upstream : modbus_tcp.upstreams()) {
                snapshot.upstreams.push_back({upstream->config().name, northbound::upstream::to_string(upstream->link_state())});
            }
        });
    sparkplug.add_sources([&] {
        r6_ensure();
        return r6.sparkplug;
    });
    gateway.add_component(sparkplug);
    gateway.add_status([&sparkplug] { return sparkplug.status(); });
    // Prometheus metrics (off without metrics_http): each collector asks its component
    // at scrape time, so a rebuilt engine or server is simply what the next scrape sees.
    namespace metrics = northbound::metrics;
    app::MetricsComponent prometheus(gateway.context(), logger, FIELDBRIDGE_VERSION);
    prometheus.add_collector([&engine](metrics::MetricSet& out) {
        if (const auto* lines = engine.engine()) metrics::collect_engine(out, *lines);
    });
    prometheus.add_collector([&modbus_tcp](metrics::MetricSet& out) {
        if (const auto* server = modbus_tcp.server()) metrics::collect_modbus_tcp(out, server->stats());
        metrics::collect_upstreams(out, modbus_tcp.upstreams());
    });
    prometheus.add_collector([&mqtt](metrics::MetricSet& out) { metrics::collect_mqtt(out, mqtt.bridge()); });
    prometheus.add_collector([&gateway](metrics::MetricSet& out) {
        metrics::collect_reloads(out, gateway.reloads().ok, gateway.reloads().rejected);
    });
    gateway.add_component(prometheus);
    return gateway.run();
}

}  // namespace

int main(int argc, char** argv) {
    try {
        daemon::CommandLine command_line(FIELDBRIDGE_VERSION);
        app::ScanCommand scan_command(std::cout, std::cerr);
        command_line.add_subcommand(scan_command);
        const auto command = command_line.parse(argc, argv, std::cout, std::cerr);
        return std::visit(
            [](const auto& chosen) -> int {
                using Chosen = std::decay_t<decltype(chosen)>;
                if constexpr (std::is_same_v<Chosen, daemon::RunCommand>) {
                    return run_gateway(chosen);
                } else if constexpr (std::is_same_v<Chosen, daemon::CheckConfigCommand>) {
                    return daemon::check_config(chosen.config_file, load, std::cout, std::cerr);
                } else if constexpr (std::is_same_v<Chosen, daemon::SubcommandCommand>) {
                    return chosen.subcommand->run(chosen.log_level);
                } else {
                    return chosen.exit_code;
                }
            },
            command);
    } catch (const std::exception& error) {
        std::cerr << "fieldbridge: internal error: " << error.what() << '\n';
        return daemon::exit_failure;
    }
}
