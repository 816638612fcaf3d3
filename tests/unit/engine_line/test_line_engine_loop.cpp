// The line core (scheduler, line master, inbox, drive loop) over a simulated bus in
// virtual time, as the line worker drives it: three live devices with injected faults
// (lost replies, noise, CRC errors, split replies), one dead device, polls, on-demand
// reads and commands, a driver that sometimes takes a request in two pieces.
// Invariants: every on_done exactly once, never a request before t3.5 of silence, a
// command goes at the very next start, the dead device is probed with back-off and
// never holds more than one request.
#include <doctest/doctest.h>

#include <functional>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;

constexpr std::uint8_t dead_address = 9;

fe::LineTimingConfig short_timeouts() {
    fe::LineTimingConfig config = default_line();
    config.response_timeout = 20ms;
    return config;
}

/// The shell of the line core in virtual time: the bus is a map of bytes by arrival
/// time, the timers are instants, a Drive runs before time moves on. Events that fall
/// on the same instant go as asio orders them: posted work, then the port's readiness,
/// then the timers.
struct Simulation {
    std::mt19937 rng{20240601};
    fe::LineCore core;
    fe::LineDelivery delivery{"A", {}};
    std::multimap<TimePoint, Bytes> rx;  // bytes the bus delivers, by time
    TimePoint now = t0;
    TimePoint last_wire = t0;  // end of the last byte on the wire, as the bus saw it

    // The shell's state.
    std::optional<TimePoint> exact_at;
    std::optional<TimePoint> lazy_at;
    std::optional<TimePoint> writable_at;
    bool drive_posted = false;
    Bytes read_buffer;  // what the last read handed over
    Bytes request;      // the request being written, as far as the driver took it

    // Bookkeeping.
    std::map<std::uint64_t, int> done_calls;  // by submission number
    std::map<std::uint64_t, OutcomeStatus> final_status;
    std::uint64_t submitted = 0;
    std::uint64_t writes = 0;
    std::uint64_t blocked_writes = 0;
    std::uint64_t early_writes = 0;
    std::uint64_t spins = 0;
    struct WaitingCommand {
        std::uint64_t number = 0;
        unsigned others_allowed = 0;  // the one in flight when it was queued, if not written yet
    };
    std::optional<WaitingCommand> command_waiting;
    std::uint64_t commands_not_next = 0;
    std::uint64_t commands_started = 0;
    std::vector<TimePoint> dead_writes;
    std::size_t max_dead_queue = 0;
    std::map<fe::DeviceIndex, bool> poll_outstanding;

    static fe::LineCoreConfig config(Duration spin_lead) {
        fe::LineCoreConfig config;
        config.name = "A";
        config.timing = short_timeouts();
        config.spin_lead = spin_lead;
        return config;
    }

    /// @p spin_lead: precise silence timing (LineCoreConfig::spin_lead), zero: off.
    explicit Simulation(Duration spin_lead) : core(config(spin_lead), "/dev/ttySIM") {
        fe::DeviceLimits limits;
        limits.read_retries = 1;
        limits.offline_after = 3;
        limits.backoff_initial = 100ms;
        limits.backoff_max = 400ms;
        for (fe::DeviceIndex d = 0; d < 4; ++d) core.scheduler().add_device(d, limits);
        feed(fe::line_event::Start{});
        REQUIRE(core.line_up());
    }

    [[nodiscard]] const fe::LineMaster& master() const { return core.master(); }
    [[nodiscard]] const fe::LineScheduler& scheduler() const { return core.scheduler(); }

    static std::uint8_t address_of(fe::DeviceIndex d) {
        return d == 3 ? dead_address : static_cast<std::uint8_t>(d + 1);
    }

    // ---- the shell ----------------------------------------------------------------

    void feed(fe::LineEvent&& event) {
        while (true) {
            const fe::LineStep step = core.handle(now, std::move(event));
            if (step.close_port) REQUIRE(core.stopped());  // this bus never fails
            if (step.exact_wake) exact_at = step.exact_wake;
            if (step.lazy_wake) lazy_at = step.lazy_wake;
            if (step.watch_writable) writable_at = now + 100us;  // the driver drains
            if (step.post_drive) drive_posted = true;
            delivery.deliver(core.scheduler());
            max_dead_queue = std::max(max_dead_queue, scheduler().online(3) ? 0 : scheduler().queued(3));
            switch (step.next) {
                case fe::LineNext::none: return;
                case fe::LineNext::resume:
                case fe::LineNext::tick: event = fe::line_event::Resume{}; break;
                case fe::LineNext::spin:
                    ++spins;
                    REQUIRE(step.spin_until > now);
                    REQUIRE(step.spin_until - now <= core.config().spin_lead);
                    now = step.spin_until;  // bytes due meanwhile are in rx for the next read
                    event = fe::line_event::Resume{};
                    break;
                case fe::LineNext::open: event = fe::line_event::Opened{"simulated"}; break;
                case fe::LineNext::read: event = read(); break;
                case fe::LineNext::write: event = write(step.write); break;
            }
        }
    }

    /// One arrival per read; the buffer counts as full while more have arrived.
    fe::LineEvent read() {
        read_buffer.clear();
        if (!rx.empty() && rx.begin()->first <= now) {
            read_buffer = rx.begin()->second;
            last_wire = std::max(last_wire, rx.begin()->first);
            rx.erase(rx.begin());
        }
        const bool more = !rx.empty() && rx.begin()->first <= now;
        return fe::line_event::BytesRead{read_buffer, more};
    }

    /// The driver takes one request in three in two pieces (it would block between).
    fe::LineEvent write(fp::ByteView bytes) {
        if (request.empty() && now < last_wire + master().timing().t3_5()) ++early_writes;
        if (request.empty() && bytes.size() > 4 && rng() % 3 == 0) {
            ++blocked_writes;
            const std::size_t piece = bytes.size() / 2;
            request.assign(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(piece));
            return fe::line_event::WriteBlocked{piece};
        }
        request.insert(request.end(), bytes.begin(), bytes.end());
        on_request(request);
        request.clear();
        return fe::line_event::Written{};
    }

    void on_request(const Bytes& bytes) {
        ++writes;
        if (bytes.front() == dead_address) dead_writes.push_back(now);
        if (command_waiting) {
            if (bytes.size() > 1 && bytes[1] == fp::fc::write_single_register) {  // only commands write
                ++commands_started;
                command_waiting.reset();
            } else if (command_waiting->others_allowed > 0) {
                --command_waiting->others_allowed;
            } else {
                ++commands_not_next;
            }
        }
        const TimePoint tx_end = now + master().timing().wire_time(bytes.size());
        last_wire = std::max(last_wire, tx_end);
        answer(bytes, tx_end);
    }

    // ---- the traffic --------------------------------------------------------------

    void submit(Transaction t, std::function<void(OutcomeStatus)> also = {}) {
        const std::uint64_t number = submitted++;
        done_calls[number] = 0;
        t.on_done = [this, number, also](const fe::Outcome& outcome) {
            ++done_calls[number];
            final_status[number] = outcome.status;
            if (also) also(outcome.status);
        };
        feed(fe::line_event::Submit{std::move(t)});
    }

    void submit_poll(fe::DeviceIndex d) {
        if (poll_outstanding[d]) return;
        poll_outstanding[d] = true;
        auto t = read_tx(d, address_of(d), Priority::poll, 0x0300, 2);
        t.poll_period = 20ms;
        submit(std::move(t), [this, d](OutcomeStatus) { poll_outstanding[d] = false; });
    }

    void submit_command(fe::DeviceIndex d) {
        if (command_waiting || scheduler().queued() == 0) return;  // one at a time, behind others
        auto t = write_tx(d, address_of(d), 0x0601, 1);
        t.deadline = now + 500ms;
        const std::uint64_t number = submitted;
        // Rule 2: it waits for the transaction in flight and nothing else.
        const auto state = master().state();
        const bool in_flight_unwritten =
            state == fe::MasterState::waiting_silence || state == fe::MasterState::sending;
        command_waiting = WaitingCommand{number, in_flight_unwritten ? 1U : 0U};
        submit(std::move(t), [this, number](OutcomeStatus) {
            if (command_waiting && command_waiting->number == number) command_waiting.reset();  // refused or expired
        });
    }

    /// The device model: the reply bytes for a request, with faults.
    void answer(const Bytes& request_bytes, TimePoint tx_end) {
        const auto framed = fp::frame_rtu_request(request_bytes);
        REQUIRE(framed.complete());
        if (framed.value.address == dead_address || framed.value.address == 0) return;
        const auto decoded = fp::decode_request(framed.value.pdu);
        REQUIRE(decoded.complete());
        Bytes reply;
        if (const auto* read_request = std::get_if<fp::ReadRegistersRequest>(&decoded.value)) {
            reply = read_reply(framed.value.address, std::vector<std::uint16_t>(read_request->count, 0x1234),
                               read_request->function);
        } else {
            const auto& write_request = std::get<fp::WriteSingleRegisterRequest>(decoded.value);
            reply = rtu(framed.value.address, fp::encode_response(fp::WriteSingleResponse{
                                                  0x06, write_request.address, write_request.value}));
        }
        const TimePoint start = tx_end + 1ms;  // device turnaround
        const auto wire = [this](std::size_t n) { return master().timing().wire_time(n); };
        const auto fault = static_cast<unsigned>(rng() % 100);
        if (fault < 3) return;  // lost
        if (fault < 13) {       // noise glued to the front
            Bytes noisy = concat({Bytes{0x00}, reply});
            rx.emplace(start + wire(noisy.size()), noisy);
        } else if (fault < 18) {  // a corrupted copy, then a good one
            Bytes bad = reply;
            bad[bad.size() - 3] ^= 0x40;  // a data bit: only the CRC can tell
            rx.emplace(start + wire(bad.size()), bad);
            rx.emplace(start + 2ms + wire(reply.size()), reply);
        } else if (fault < 25) {  // one byte per read
            for (std::size_t i = 0; i < reply.size(); ++i) rx.emplace(start + wire(i + 1), Bytes{reply[i]});
        } else {
            rx.emplace(start + wire(reply.size()), reply);
        }
    }

    /// Runs until @p until; returns when idle with nothing due.
    void run(TimePoint until, bool traffic) {
        TimePoint next_poll = now;
        TimePoint next_read = now;
        TimePoint next_command = now + 13ms;
        std::uniform_int_distribution<int> live(0, 2);
        std::uniform_int_distribution<int> any(0, 3);
        for (int guard = 0; guard < 2'000'000; ++guard) {
            if (traffic) {
                while (next_poll <= now) {
                    for (fe::DeviceIndex d = 0; d < 4; ++d) submit_poll(d);
                    next_poll += 20ms;
                }
                while (next_read <= now) {
                    const auto d = static_cast<fe::DeviceIndex>(any(rng));
                    submit(read_tx(d, address_of(d), Priority::on_demand, 0x0000, 4));
                    next_read += 7ms;
                }
                while (next_command <= now) {
                    submit_command(static_cast<fe::DeviceIndex>(live(rng)));
                    next_command += 31ms;
                }
            }
            if (drive_posted) {
                drive_posted = false;
                feed(fe::line_event::Drive{});
                continue;
            }
            if (!rx.empty() && rx.begin()->first <= now) {
                feed(fe::line_event::Readable{});
                continue;
            }
            if (writable_at && *writable_at <= now) {
                writable_at.reset();
                feed(fe::line_event::Writable{});
                continue;
            }
            if (exact_at && *exact_at <= now) {
                exact_at.reset();
                feed(fe::line_event::TimerFired{fe::WakeTimer::exact});
                continue;
            }
            if (lazy_at && *lazy_at <= now) {
                lazy_at.reset();
                feed(fe::line_event::TimerFired{fe::WakeTimer::lazy});
                continue;
            }
            // Nothing due: advance virtual time to the next thing that happens.
            std::optional<TimePoint> next;
            const auto consider = [&next](std::optional<TimePoint> t) {
                if (t && (!next || *t < *next)) next = t;
            };
            consider(exact_at);
            consider(lazy_at);
            consider(writable_at);
            if (!rx.empty()) consider(rx.begin()->first);
            if (traffic) {
                consider(next_poll);
                consider(next_read);
                consider(next_command);
            }
            if (!next || now >= until) return;
            REQUIRE(*next >= now);
            now = *next;
        }
        FAIL("the simulation did not settle");
    }
};

void run_mixed_traffic(Simulation& sim) {
    sim.run(t0 + 2s, true);
    // Drain: no new traffic; everything queued is served or probed.
    sim.run(t0 + 10s, false);
    CHECK_FALSE(sim.master().busy());
    CHECK(sim.scheduler().queued() == 0);
    sim.feed(fe::line_event::Stop{});

    // Every transaction completed exactly once.
    std::uint64_t not_once = 0;
    for (const auto& [number, calls] : sim.done_calls) not_once += calls == 1 ? 0 : 1;
    CHECK(not_once == 0);
    CHECK(sim.done_calls.size() == sim.submitted);
    CHECK(sim.submitted > 500);

    // Never a request before t3.5 of silence after the last byte on the wire.
    CHECK(sim.early_writes == 0);
    const auto& c = sim.master().counters();
    CHECK(sim.writes == c.requests + c.broadcasts);
    CHECK(sim.blocked_writes > 50);  // and resumed: every request went out whole

    // Commands went at the very next start after they were queued.
    CHECK(sim.commands_started > 20);
    CHECK(sim.commands_not_next == 0);

    // The faults happened and were handled.
    CHECK(c.crc_errors > 0);
    CHECK(c.garbage_bytes > 0);
    CHECK(c.timeouts > 0);
    CHECK(c.replies > 300);
    std::map<OutcomeStatus, int> by_status;
    for (const auto& [number, status] : sim.final_status) ++by_status[status];
    CHECK(by_status[OutcomeStatus::ok] > 300);
    CHECK(by_status[OutcomeStatus::device_offline] > 0);

    // The dead device went offline, held at most one request, and was probed with
    // back-off (100, 200, 400, 400 ... ms apart, never closer than 100 ms).
    CHECK_FALSE(sim.scheduler().online(3));
    CHECK(sim.max_dead_queue <= 1);
    REQUIRE(sim.dead_writes.size() >= 5);
    std::size_t closer = 0;
    for (std::size_t i = 4; i < sim.dead_writes.size(); ++i) {
        if (sim.dead_writes[i] - sim.dead_writes[i - 1] < 100ms) ++closer;
    }
    CHECK(closer == 0);
    CHECK(sim.dead_writes.size() < 40);  // 2 s of polling at 20 ms would be 100
    // The live devices stayed online despite lost replies (retries absorb single losses).
    CHECK(sim.scheduler().online(0));
    CHECK(sim.scheduler().online(1));
    CHECK(sim.scheduler().online(2));
}

TEST_CASE("engine loop: two virtual seconds of mixed traffic over a faulty bus") {
    Simulation sim(Duration::zero());
    run_mixed_traffic(sim);
    CHECK(sim.spins == 0);
}

TEST_CASE("engine loop: the same with precise silence timing (the silences end in spins)") {
    Simulation sim(200us);
    run_mixed_traffic(sim);
    CHECK(sim.spins > 300);
}

}  // namespace
