#include "pty_bus.hpp"

#include <asio/error.hpp>
#include <fmt/format.h>

#include "durations.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

PtyBus::PtyBus(asio::io_context& io, std::filesystem::path link, std::unique_ptr<BusEngine> engine,
               std::shared_ptr<spdlog::logger> log)
    : io_(io),
      link_(std::move(link)),
      engine_(std::move(engine)),
      log_(std::move(log)),
      output_timer_(io),
      resync_timer_(io),
      replug_timer_(io) {}

PtyBus::~PtyBus() { close(); }

void PtyBus::open() {
    port_ = std::make_unique<PtyPort>(io_, link_);
    watch_opens();
    closed_ = false;
    log_->info("{}: {} -> {} ({} device(s), {} bps, wire time {})", name(), link_.string(),
               port_->slave_name(), engine_->stats(Clock::now())["devices"].size(),
               engine_->settings().timing.baud, engine_->settings().wire_time ? "on" : "off");
    start_read();
}

void PtyBus::close() {
    closed_ = true;
    asio::error_code ignored;
    replug_timer_.cancel();
    output_timer_.cancel();
    resync_timer_.cancel();
    output_armed_.reset();
    resync_armed_.reset();
    if (port_) {
        unwatch_opens();
        port_.reset();
        log_->info("{}: closed, {} removed", name(), link_.string());
    }
}

void PtyBus::unplug(std::chrono::nanoseconds downtime) {
    if (!port_) {
        throw SimError(fmt::format("{}: already unplugged; wait for it to come back", name()));
    }
    engine_->count_unplug();
    engine_->reset_line();
    output_timer_.cancel();
    resync_timer_.cancel();
    output_armed_.reset();
    resync_armed_.reset();
    unwatch_opens();
    port_.reset();
    log_->warn("{}: unplugged: pty closed and {} removed for {}", name(), link_.string(),
               format_duration(downtime));
    replug_timer_.expires_after(downtime);
    replug_timer_.async_wait([this](const asio::error_code& e) { on_replug_timer(e); });
}

void PtyBus::on_replug_timer(const asio::error_code& error) {
    if (error || closed_ || port_) {
        return;
    }
    try {
        port_ = std::make_unique<PtyPort>(io_, link_);
        watch_opens();
        log_->warn("{}: plugged back in: {} -> {}", name(), link_.string(), port_->slave_name());
        start_read();
    } catch (const std::exception& e) {
        // The bus stays unplugged; the operator sees why and can retry with `fault`.
        log_->error("{}: could not come back after unplug: {}", name(), e.what());
    }
}

void PtyBus::apply_fault(const FaultSpec& spec) {
    if (spec.kind == FaultKind::unplug) {
        unplug(spec.duration);
        return;
    }
    engine_->apply_fault(spec);
}

void PtyBus::tick(Clock::time_point now) {
    engine_->advance(now);
}

nlohmann::json PtyBus::stats(Clock::time_point now) const {
    auto json = engine_->stats(now);
    json["path"] = link_.string();
    json["pty"] = port_ ? nlohmann::json(port_->slave_name()) : nlohmann::json(nullptr);
    json["connected"] = port_ != nullptr;
    // Opens of the line's port by the gateway since the simulator started (a reopen
    // after a failure or a restart of the line counts one more).
    json["port_opens"] = opens_before_ + (opens_watch_ ? opens_watch_->opens() : 0);
    json["port_closes"] = closes_before_ + (opens_watch_ ? opens_watch_->closes() : 0);
    return json;
}

void PtyBus::watch_opens() {
    try {
        opens_watch_ = std::make_unique<PtyOpenWatch>(io_, port_->slave_name());
    } catch (const std::exception& e) {
        // The bus works without it; only the `port_opens` count stays still.
        log_->warn("{}: {}", name(), e.what());
    }
}

void PtyBus::unwatch_opens() {
    if (!opens_watch_) return;
    opens_before_ += opens_watch_->opens();
    closes_before_ += opens_watch_->closes();
    opens_watch_.reset();
}

void PtyBus::start_read() {
    if (!port_) {
        return;
    }
    port_->master().async_read_some(asio::buffer(rx_buffer_),
                                    [this](const asio::error_code& e, std::size_t n) { on_read(e, n); });
}

void PtyBus::on_read(const asio::error_code& error, std::size_t count) {
    if (error == asio::error::operation_aborted || !port_) {
        return;
    }
    if (error) {
        // EIO cannot happen while we hold the slave open; anything else is fatal for
        // this pty: report it and leave the bus unplugged rather than spin.
        log_->error("{}: reading the pty master failed: {}; the bus stops answering",
                    name(), error.message());
        return;
    }
    try {
        engine_->on_bytes(protocol::ByteView(rx_buffer_.data(), count), Clock::now());
        flush_due();
    } catch (const std::exception& e) {
        log_->error("{}: frame handling failed: {}", name(), e.what());
    }
    arm_timers();
    start_read();
}

void PtyBus::flush_due() {
    if (!port_) {
        return;
    }
    for (const auto& output : engine_->take_due(Clock::now())) {
        const auto written = port_->write(output.bytes);
        const auto when = Clock::now();
        engine_->on_written(output, written, when);
        if (written < output.bytes.size()) {
            log_->warn("{}: pty accepted {} of {} bytes (is anything reading {}?)", name(), written,
                       output.bytes.size(), link_.string());
        }
    }
}

void PtyBus::arm_timers() {
    const auto next = engine_->next_output();
    if (next != output_armed_) {
        output_armed_ = next;
        if (next) {
            // Wire time: wake early and spin the rest (on_output_timer), so a reply
            // leaves when the emulated line says, not when the scheduler wakes us.
            output_timer_.expires_at(engine_->settings().wire_time ? *next - output_spin_lead : *next);
            output_timer_.async_wait([this](const asio::error_code& e) { on_output_timer(e); });
        } else {
            output_timer_.cancel();
        }
    }
    const auto resync = engine_->resync_deadline();
    if (resync != resync_armed_) {
        resync_armed_ = resync;
        if (resync) {
            resync_timer_.expires_at(*resync);
            resync_timer_.async_wait([this](const asio::error_code& e) { on_resync_timer(e); });
        } else {
            resync_timer_.cancel();
        }
    }
}

void PtyBus::on_output_timer(const asio::error_code& error) {
    if (error == asio::error::operation_aborted) {
        return;
    }
    output_armed_.reset();
    if (const auto due = engine_->next_output(); due && engine_->settings().wire_time) {
        while (Clock::now() < *due) {
            // A real UART starts shifting at its instant; at most output_spin_lead.
        }
    }
    try {
        flush_due();
    } catch (const std::exception& e) {
        log_->error("{}: writing a reply failed: {}", name(), e.what());
    }
    arm_timers();
}

void PtyBus::on_resync_timer(const asio::error_code& error) {
    if (error == asio::error::operation_aborted) {
        return;
    }
    resync_armed_.reset();
    const auto now = Clock::now();
    const auto deadline = engine_->resync_deadline();
    try {
        if (deadline && *deadline <= now) {
            engine_->on_silence(now);
            flush_due();
        }
    } catch (const std::exception& e) {
        log_->error("{}: resynchronisation failed: {}", name(), e.what());
    }
    arm_timers();
}

}  // namespace fieldbridge::sim::runtime
