#include "engine/line_worker.hpp"

#include <sys/prctl.h>

#include <asio/error.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "engine/line_delivery.hpp"
#include "engine/line_worker_port.hpp"

namespace fieldbridge::engine {

void tighten_timer_slack() noexcept { ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL); }

class LineWorker::Impl {
    /// A wake timer of the core, and a generation that tells its current wait from
    /// one it replaced (a wait already completed when it was re-set).
    struct Wake {
        Wake(asio::io_context& io, WakeTimer kind) : timer(io), which(kind) {}
        asio::steady_timer timer;
        WakeTimer which;
        std::uint64_t generation = 0;
    };

public:
    Impl(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port, LogSink log,
         LineWorkerSeams seams)
        : io_(io),
          seams_(seams),
          log_(log),
          core_(std::move(config), port ? port->settings().path : std::string{}, log),
          delivery_(core_.config().name, std::move(log)),
          port_(io, std::move(port)),
          exact_(io, WakeTimer::exact),
          lazy_(io, WakeTimer::lazy),
          reopen_timer_(io),
          connect_timer_(io) {}

    ~Impl() { stop(); }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    LineScheduler& scheduler() noexcept { return core_.scheduler(); }
    const LineScheduler& scheduler() const noexcept { return core_.scheduler(); }
    const LineMaster& master() const noexcept { return core_.master(); }
    const LineWorkerConfig& config() const noexcept { return core_.config(); }
    bool line_up() const noexcept { return core_.line_up(); }
    std::uint64_t reopens() const noexcept { return core_.reopens(); }
    void set_state_callback(LineStateCallback callback) { on_state_ = std::move(callback); }
    void set_health_callback(HealthCallback callback) { delivery_.set_health_callback(std::move(callback)); }

    void start() {
        if (!core_.stopped()) seams_.set_timer_slack();
        feed(line_event::Start{});
    }

    void stop() { feed(line_event::Stop{}); }

    void remove_device(DeviceIndex device, OutcomeStatus status) {
        feed(line_event::RemoveDevice{device, status, false});
    }
    void drop_polls(DeviceIndex device) { feed(line_event::RemoveDevice{device, OutcomeStatus::cancelled, true}); }

    void submit(Transaction transaction) {
        const LineStep step = core_.handle(seams_.now(), line_event::Submit{std::move(transaction)});
        apply(step);
        // A submission after stop(), or one the scheduler refused while the line
        // waits (line_core.hpp), completes at once: on the loop, never inside
        // submit(), and self-contained because the worker may be gone by then.
        if (core_.has_deliveries()) {
            std::vector<LineCompletion> cancelled;
            core_.scheduler().take_completions(cancelled);
            asio::post(io_, [cancelled = std::move(cancelled), log = log_, line = config().name]() mutable {
                for (LineCompletion& completion : cancelled) LineDelivery::complete(completion, log, line);
            });
        }
    }

private:
    /// Wraps a handler so that it does nothing once this Impl is gone: asio may still
    /// hold aborted waits after stop() and destruction.
    template <typename Function>
    auto guarded(Function function) {
        return [alive = std::weak_ptr<char>(alive_), this, function = std::move(function)](auto&&... args) mutable {
            if (alive.expired()) return;
            function(std::forward<decltype(args)>(args)...);
        };
    }

    /// One event and the steps it leads to: effects, deliveries, then the answer to
    /// the core's question, until it asks nothing.
    void feed(LineEvent event) {
        while (true) {
            const TimePoint now = seams_.now();
            const LineStep step = core_.handle(now, std::move(event));
            apply(step);
            delivery_.deliver(core_.scheduler());
            if (step.line_up) notify_state(*step.line_up, now);
            switch (step.next) {
                case LineNext::none: return;
                case LineNext::resume:
                case LineNext::tick: event = line_event::Resume{}; break;
                case LineNext::spin:
                    spin_until(step.spin_until);
                    event = line_event::Resume{};
                    break;
                case LineNext::open: event = open(); break;
                case LineNext::read: event = read(); break;
                case LineNext::write: event = write(step.write); break;
            }
        }
    }

    void apply(const LineStep& step) {
        if (step.close_port) {
            // A connect in progress ends with the port: its wait is aborted, its timer
            // must not fire into the next open.
            ++connect_generation_;
            connect_timer_.cancel();
            port_.close();
        }
        if (step.cancel_timers) {
            exact_.timer.cancel();
            lazy_.timer.cancel();
            reopen_timer_.cancel();
        }
        if (step.exact_wake) set(exact_, *step.exact_wake);
        if (step.lazy_wake) set(lazy_, *step.lazy_wake);
        if (step.reopen_at) {
            reopen_timer_.expires_at(*step.reopen_at);
            reopen_timer_.async_wait(guarded([this](const asio::error_code& error) {
                if (error != asio::error::operation_aborted) feed(line_event::ReopenDue{});
            }));
        }
        if (step.watch_readable && port_.is_open()) {
            port_.wait_readable(guarded([this](const asio::error_code& error) {
                if (error != asio::error::operation_aborted) feed(line_event::Readable{});
            }));
        }
        if (step.watch_writable && port_.is_open()) {
            port_.wait_writable(guarded([this](const asio::error_code& error) {
                if (error != asio::error::operation_aborted) feed(line_event::Writable{});
            }));
        }
        if (step.post_drive) asio::post(io_, guarded([this] { feed(line_event::Drive{}); }));
    }

    void set(Wake& wake, TimePoint until) {
        const std::uint64_t generation = ++wake.generation;
        wake.timer.expires_at(until);
        wake.timer.async_wait(guarded([this, &wake, generation](const asio::error_code& error) {
            if (error == asio::error::operation_aborted || generation != wake.generation) return;
            feed(line_event::TimerFired{wake.which});
        }));
    }

    // ---- the answers to the core's questions ------------------------------------------

    /// Precise silence timing: the loop thread busy-waits the last stretch of a
    /// silence (at most the core's spin lead), so the request leaves at the instant
    /// rather than when a timer wake-up gets round to it. Nothing else on the loop
    /// runs meanwhile.
    void spin_until(TimePoint until) const noexcept {
        while (seams_.now() < until) {
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#endif
        }
    }

    LineEvent open() {
        try {
            port_.open();
        } catch (const SerialPortError& error) {
            return line_event::OpenFailed{error.what()};
        }
        if (port_.opening()) {
            await_connect();
            return line_event::OpenPending{};
        }
        return line_event::Opened{port_.open_detail()};
    }

    /// A TCP connect runs: the loop goes on, and the connect's end (the fd writable) or
    /// its timeout feeds Opened / OpenFailed.
    void await_connect() {
        const std::uint64_t generation = ++connect_generation_;
        const auto timeout = port_.open_timeout();
        connect_timer_.expires_after(timeout);
        connect_timer_.async_wait(guarded([this, generation, timeout](const asio::error_code& error) {
            if (error == asio::error::operation_aborted || generation != connect_generation_) return;
            ++connect_generation_;
            port_.close();
            feed(line_event::OpenFailed{core_.port_path() + ": no answer within " + std::to_string(timeout.count()) +
                                        " ms (connect_timeout); check that the device server is powered and "
                                        "reachable and that its address and port are right"});
        }));
        port_.wait_writable(guarded([this, generation](const asio::error_code& error) {
            if (error == asio::error::operation_aborted || generation != connect_generation_) return;
            ++connect_generation_;
            connect_timer_.cancel();
            try {
                port_.finish_open();
            } catch (const SerialPortError& failure) {
                feed(line_event::OpenFailed{failure.what()});
                return;
            }
            feed(line_event::Opened{port_.open_detail()});
        }));
    }

    LineEvent read() {
        try {
            const protocol::ByteView bytes = port_.read_some();
            return line_event::BytesRead{bytes, port_.buffer_filled()};
        } catch (const SerialPortError& error) {
            return line_event::PortFailed{"read", error.what()};
        }
    }

    LineEvent write(protocol::ByteView bytes) {
        std::size_t sent = 0;
        try {
            while (sent < bytes.size()) {
                const std::size_t n = port_.write_some(bytes.subspan(sent));
                if (n == 0) return line_event::WriteBlocked{sent};
                sent += n;
            }
        } catch (const SerialPortError& error) {
            return line_event::PortFailed{"write", error.what()};
        }
        return line_event::Written{};
    }

    void notify_state(bool up, TimePoint now) {
        if (!on_state_) return;
        try {
            on_state_(up, now);
        } catch (const std::exception& error) {
            log_(LogLevel::error, "line " + config().name + ": the line state callback threw: " + error.what());
        }
    }

    asio::io_context& io_;
    LineWorkerSeams seams_;
    LogSink log_;
    LineCore core_;
    LineDelivery delivery_;
    LinePort port_;
    Wake exact_;  ///< short waits, set to the instant
    Wake lazy_;   ///< long waits, may wake early (LineCore::arm_wake)
    asio::steady_timer reopen_timer_;
    asio::steady_timer connect_timer_;  ///< a TCP connect's timeout
    std::uint64_t connect_generation_ = 0;  ///< tells the current connect from one that ended
    LineStateCallback on_state_;
    std::shared_ptr<char> alive_ = std::make_shared<char>('\0');
};

LineWorker::LineWorker(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port, LogSink log,
                       LineWorkerSeams seams)
    : impl_(std::make_unique<Impl>(io, std::move(config), std::move(port), std::move(log), seams)) {}

LineWorker::~LineWorker() {
    // Stopped while every member is alive: a completion may still call submit().
    impl_->stop();
}

LineScheduler& LineWorker::scheduler() noexcept { return impl_->scheduler(); }
const LineScheduler& LineWorker::scheduler() const noexcept { return std::as_const(*impl_).scheduler(); }
void LineWorker::set_state_callback(LineStateCallback callback) { impl_->set_state_callback(std::move(callback)); }
void LineWorker::set_health_callback(HealthCallback callback) { impl_->set_health_callback(std::move(callback)); }
void LineWorker::start() { impl_->start(); }
void LineWorker::stop() { impl_->stop(); }
void LineWorker::submit(Transaction transaction) { impl_->submit(std::move(transaction)); }
void LineWorker::remove_device(DeviceIndex device, OutcomeStatus status) { impl_->remove_device(device, status); }
void LineWorker::drop_polls(DeviceIndex device) { impl_->drop_polls(device); }
bool LineWorker::line_up() const noexcept { return impl_->line_up(); }
const LineMaster& LineWorker::master() const noexcept { return impl_->master(); }
const LineWorkerConfig& LineWorker::config() const noexcept { return impl_->config(); }
std::uint64_t LineWorker::reopens() const noexcept { return impl_->reopens(); }

}  // namespace fieldbridge::engine
