#include "simulator.hpp"

#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <random>

#include <asio/ip/address.hpp>

#include "models/device_factory.hpp"
#include "models/r6_model.hpp"
#include "protocol/rtu_frame.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

constexpr auto stats_period = std::chrono::seconds(1);

/// splitmix64: independent, reproducible seeds for each bus from the one --seed.
std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream) {
    std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

}  // namespace

Simulator::Simulator(asio::io_context& io, SimOptions options, std::shared_ptr<spdlog::logger> log)
    : io_(io),
      options_(std::move(options)),
      log_(std::move(log)),
      started_(Clock::now()),
      tick_timer_(io),
      stats_timer_(io) {}

Simulator::~Simulator() { shutdown(); }

void Simulator::start() {
    started_ = Clock::now();
    std::uint64_t seed = 0;
    if (options_.seed) {
        seed = *options_.seed;
    } else {
        std::random_device entropy;
        seed = (static_cast<std::uint64_t>(entropy()) << 32) | entropy();
        log_->info("fault seed {} (pass --seed {} to repeat this run)", seed, seed);
    }
    const LineTiming timing{options_.baud,
                            protocol::bits_per_character(options_.parity != 'N', options_.stop_bits)};
    std::uint64_t stream = 0;
    for (const auto& spec : options_.buses) {
        std::vector<std::unique_ptr<BusDevice>> devices;
        for (const auto& device : spec.devices) {
            try {
                devices.push_back(make_device(device.type, device.address, device.options));
            } catch (const std::invalid_argument& e) {
                throw SimError(fmt::format("--bus {}: device {}@{}: {}", spec.name, device.type,
                                           device.address, e.what()));
            }
        }
        BusSettings settings{spec.name, timing, options_.wire_time, options_.turnaround,
                             mix_seed(seed, stream++)};
        auto engine = std::make_unique<BusEngine>(std::move(settings), std::move(devices), log_,
                                                  Clock::now());
        buses_.push_back(std::make_unique<PtyBus>(io_, spec.link, std::move(engine), log_));
    }
    running_ = true;
    for (auto& bus : buses_) {
        bus->open();
    }
    for (const auto& fault : options_.faults) {
        bus_named(fault.bus).apply_fault(fault);
    }
    if (options_.r6) {
        r6_model_ = std::make_unique<R6Model>();
        asio::error_code ec;
        const auto address = asio::ip::make_address(options_.r6->host, ec);
        if (ec) {
            throw SimError(fmt::format("--r6: '{}' is not an IP address (use e.g. 127.0.0.1)",
                                       options_.r6->host));
        }
        auto* model = r6_model_.get();
        r6_server_ = std::make_unique<ModbusTcpServer>(
            io_, asio::ip::tcp::endpoint(address, options_.r6->port), options_.r6_unit,
            [model](protocol::ByteView pdu, Clock::time_point now) { return model->handle_pdu(pdu, now); },
            log_);
        r6_server_->open();
    }
    if (options_.control) {
        control_ = std::make_unique<ControlServer>(
            io_, *options_.control, [this](std::string_view line) { return command(line); }, log_);
        control_->open();
    }
    tick_timer_.expires_after(options_.tick);
    tick_timer_.async_wait([this](const asio::error_code& e) { on_tick(e); });
    if (options_.stats_file) {
        write_stats_file();
        stats_timer_.expires_after(stats_period);
        stats_timer_.async_wait([this](const asio::error_code& e) { on_stats_timer(e); });
    }
}

void Simulator::shutdown() {
    if (!running_) {
        return;
    }
    running_ = false;
    tick_timer_.cancel();
    stats_timer_.cancel();
    if (control_) {
        control_->close();
    }
    if (r6_server_) {
        r6_server_->close();
    }
    for (auto& bus : buses_) {
        bus->close();
    }
    if (options_.stats_file) {
        write_stats_file();
    }
    log_->info("simulator stopped");
}

void Simulator::on_tick(const asio::error_code& error) {
    if (error || !running_) {
        return;
    }
    const auto now = Clock::now();
    for (auto& bus : buses_) {
        try {
            bus->tick(now);
        } catch (const std::exception& e) {
            log_->error("{}: a device model failed to advance: {}", bus->name(), e.what());
        }
    }
    // Period from the previous expiry, not from now: the tick does not drift.
    tick_timer_.expires_at(tick_timer_.expiry() + options_.tick);
    if (tick_timer_.expiry() < now) {
        tick_timer_.expires_after(options_.tick);
    }
    tick_timer_.async_wait([this](const asio::error_code& e) { on_tick(e); });
}

void Simulator::on_stats_timer(const asio::error_code& error) {
    if (error || !running_) {
        return;
    }
    write_stats_file();
    stats_timer_.expires_at(stats_timer_.expiry() + stats_period);
    stats_timer_.async_wait([this](const asio::error_code& e) { on_stats_timer(e); });
}

void Simulator::write_stats_file() const {
    const auto& path = *options_.stats_file;
    auto temp = path;
    temp += ".tmp";
    {
        std::ofstream out(temp, std::ios::trunc);
        out << stats().dump(2) << '\n';
        if (!out) {
            log_->error("cannot write the stats file {}; check the directory exists and is "
                        "writable",
                        temp.string());
            return;
        }
    }
    // Rename: a reader never sees a half-written file.
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) {
        log_->error("cannot move {} to {}: {}", temp.string(), path.string(), ec.message());
    }
}

nlohmann::json Simulator::stats() const {
    const auto now = Clock::now();
    nlohmann::json json;
    json["uptime_s"] = std::chrono::duration<double>(now - started_).count();
    auto buses = nlohmann::json::object();
    for (const auto& bus : buses_) {
        buses[bus->name()] = bus->stats(now);
    }
    json["buses"] = std::move(buses);
    json["r6"] = r6_server_ ? r6_server_->stats() : nlohmann::json(nullptr);
    return json;
}

PtyBus& Simulator::bus_named(std::string_view name) {
    for (auto& bus : buses_) {
        if (bus->name() == name) {
            return *bus;
        }
    }
    std::string known;
    for (const auto& bus : buses_) {
        known += (known.empty() ? "" : ", ") + bus->name();
    }
    throw SimError(fmt::format("no bus named '{}' (buses: {})", name, known.empty() ? "none" : known));
}

}  // namespace fieldbridge::sim::runtime
