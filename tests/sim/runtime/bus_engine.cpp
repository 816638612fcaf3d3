#include "bus_engine.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "durations.hpp"
#include "protocol/rtu_frame.hpp"
#include "protocol/wtec_ascii_frame.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

constexpr std::uint8_t ascii_start = '>';
/// Gap violations are logged at warning level this many times, then at debug level,
/// so a misbehaving master cannot flood the log.
constexpr std::uint64_t gap_warnings = 10;
/// Without emulated wire time the resynchronisation silence still needs a floor: a
/// pty delivers a frame in one read, but a master that writes it in pieces should
/// not have it cut at 0.3 ms.
constexpr auto resync_floor = std::chrono::milliseconds(2);

/// "02 03 06 00 00 01 84 B1": the spelling of the manuals' frame tables, so a trace
/// can be compared with them (and with tests/vectors) by eye or by a test.
[[nodiscard]] std::string hex_bytes(const protocol::Bytes& bytes) {
    std::string text;
    text.reserve(bytes.size() * 3);
    for (const std::uint8_t b : bytes) {
        if (!text.empty()) text += ' ';
        text += fmt::format("{:02X}", b);
    }
    return text;
}

}  // namespace

BusEngine::BusEngine(BusSettings settings, std::vector<std::unique_ptr<BusDevice>> devices,
                     std::shared_ptr<spdlog::logger> log, Clock::time_point now)
    : settings_(std::move(settings)), log_(std::move(log)), faults_(settings_.seed), started_(now) {
    for (auto& device : devices) {
        if (device->protocol() == BusProtocol::wtec_ascii) {
            has_ascii_ = true;
        } else {
            has_rtu_ = true;
        }
        slots_.push_back(Slot{std::move(device), {}, false});
    }
}

// ---- input ----------------------------------------------------------------------

void BusEngine::on_bytes(protocol::ByteView bytes, Clock::time_point now) {
    if (bytes.empty()) {
        return;
    }
    wire_.bytes_in += bytes.size();
    wire_.busy += settings_.timing.bytes(bytes.size());
    last_arrival_ = now;
    if (reply_pending(now)) {
        // The device is answering: these bytes meet its reply on the line.
        rx_.insert(rx_.end(), bytes.begin(), bytes.end());
        rx_end_.insert(rx_end_.end(), bytes.size(), now);
        collide(rx_.size(), now);
        return;
    }
    // On the emulated wire the burst starts when the line is free and its bytes
    // follow each other; times are computed from the burst start so rounding never
    // accumulates.
    const auto burst_start = settings_.wire_time ? std::max(now, line_free_) : now;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        rx_.push_back(bytes[i]);
        rx_end_.push_back(settings_.wire_time ? burst_start + settings_.timing.bytes(i + 1) : now);
    }
    if (settings_.wire_time) {
        line_free_ = rx_end_.back();
    }
    process(now);
}

std::optional<Clock::time_point> BusEngine::resync_deadline() const {
    if (rx_.empty()) {
        return std::nullopt;
    }
    const auto silence = std::max<Clock::duration>(settings_.timing.silence(), resync_floor);
    return std::max(last_arrival_, rx_end_.back()) + silence;
}

void BusEngine::on_silence(Clock::time_point now) {
    // Nothing more is coming: a frame can only still be found further in.
    while (!rx_.empty()) {
        discard(1, Discard::garbage, now);
        process(now);
    }
}

BusEngine::Attempt BusEngine::frame_head() const {
    Attempt attempt;
    const protocol::ByteView rx(rx_);
    if (rx[0] == ascii_start && has_ascii_) {
        const auto result = protocol::wtec::scan_frame(rx);
        if (result.need_more()) {
            return attempt;
        }
        if (result.malformed()) {
            attempt.what = Framed::drop;
            attempt.length = std::max<std::size_t>(result.consumed, 1);
            attempt.crc_error = result.error == protocol::DecodeError::bad_crc;
            return attempt;
        }
        const auto length = protocol::wtec::encode_frame(result.value).size();
        attempt.what = Framed::frame;
        attempt.skipped = result.consumed > length ? result.consumed - length : 0;
        attempt.length = result.consumed - attempt.skipped;
        attempt.protocol = BusProtocol::wtec_ascii;
        attempt.address = result.value.address;
        return attempt;
    }
    if (has_rtu_) {
        const auto result = protocol::frame_rtu_request(rx);
        if (result.need_more()) {
            return attempt;
        }
        if (result.malformed()) {
            attempt.what = Framed::drop;
            attempt.length = std::max<std::size_t>(result.consumed, 1);
            attempt.crc_error = result.error == protocol::DecodeError::bad_crc;
            return attempt;
        }
        const auto length = result.value.pdu.size() + 3;  // address + PDU + CRC
        attempt.what = Framed::frame;
        attempt.skipped = result.consumed > length ? result.consumed - length : 0;
        attempt.length = result.consumed - attempt.skipped;
        attempt.protocol = BusProtocol::modbus_rtu;
        attempt.address = result.value.address;
        return attempt;
    }
    // An ASCII-only bus: everything up to the next '>' is noise.
    const auto start = std::find(rx_.begin() + 1, rx_.end(), ascii_start);
    attempt.what = Framed::drop;
    attempt.length = static_cast<std::size_t>(start - rx_.begin());
    return attempt;
}

void BusEngine::process(Clock::time_point now) {
    while (!rx_.empty()) {
        if (reply_pending(now)) {
            collide(rx_.size(), now);
            return;
        }
        const auto attempt = frame_head();
        switch (attempt.what) {
            case Framed::more: return;
            case Framed::drop:
                discard(attempt.length, attempt.crc_error ? Discard::crc_error : Discard::garbage, now);
                break;
            case Framed::frame:
                if (attempt.skipped > 0) {
                    discard(attempt.skipped, Discard::garbage, now);
                }
                handle_frame(attempt, now);
                break;
        }
    }
}

void BusEngine::discard(std::size_t count, Discard why, Clock::time_point now) {
    count = std::min(count, rx_.size());
    if (count == 0) {
        return;
    }
    if (why == Discard::crc_error) {
        ++wire_.crc_errors;
        log_->debug("{}: request with a bad CRC dropped ({} bytes)", settings_.name, count);
    } else {
        wire_.garbage_bytes += count;
        log_->debug("{}: {} garbage byte(s) skipped", settings_.name, count);
    }
    const auto end = rx_end_[count - 1];
    if (faults_.decide_echo()) {
        ++wire_.echoes;
        schedule(Output{settings_.wire_time ? end : now, protocol::Bytes(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(count)), false});
    }
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(count));
    rx_end_.erase(rx_end_.begin(), rx_end_.begin() + static_cast<std::ptrdiff_t>(count));
}

void BusEngine::collide(std::size_t count, Clock::time_point now) {
    ++wire_.collisions;
    wire_.collision_bytes += count;
    log_->warn("{}: collision: {} byte(s) sent while a device reply was pending; discarded "
               "(the master must wait for the reply or its timeout)",
               settings_.name, count);
    if (faults_.decide_echo()) {
        ++wire_.echoes;
        schedule(Output{now, protocol::Bytes(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(count)), false});
    }
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(count));
    rx_end_.erase(rx_end_.begin(), rx_end_.begin() + static_cast<std::ptrdiff_t>(count));
}

void BusEngine::note_silence(Clock::time_point frame_start) {
    ++window_requests_;
    if (!last_frame_end_) {
        return;
    }
    const auto silence = std::max(frame_start - *last_frame_end_, Clock::duration::zero());
    const auto silence_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(silence);
    if (wire_.min_silence.count() < 0 || silence_ns < wire_.min_silence) {
        wire_.min_silence = silence_ns;
    }
    window_max_silence_ = std::max(window_max_silence_, silence_ns);
    if (silence_ns < settings_.timing.silence()) {
        ++wire_.gap_violations;
        const auto level = wire_.gap_violations <= gap_warnings ? spdlog::level::warn
                                                                : spdlog::level::debug;
        log_->log(level,
                  "{}: gap violation #{}: request started {} after the previous frame, "
                  "3.5 characters are {} at {} bps",
                  settings_.name, wire_.gap_violations, format_duration(silence),
                  format_duration(settings_.timing.silence()), settings_.timing.baud);
    }
}

nlohmann::json BusEngine::take_silence_window() {
    nlohmann::json window{{"requests", window_requests_},
                          {"max_silence_us", std::chrono::duration<double, std::micro>(window_max_silence_).count()}};
    window_requests_ = 0;
    window_max_silence_ = {};
    return window;
}

void BusEngine::handle_frame(const Attempt& attempt, Clock::time_point now) {
    const auto n = static_cast<std::ptrdiff_t>(attempt.length);
    const protocol::Bytes frame(rx_.begin(), rx_.begin() + n);
    const auto start = settings_.wire_time ? rx_end_.front() - settings_.timing.character()
                                           : rx_end_.front();
    const auto end = rx_end_[attempt.length - 1];
    rx_.erase(rx_.begin(), rx_.begin() + n);
    rx_end_.erase(rx_end_.begin(), rx_end_.begin() + n);

    ++wire_.requests;
    if (log_->should_log(spdlog::level::trace)) {
        log_->trace("{}: request {}", settings_.name, hex_bytes(frame));
    }
    note_silence(start);
    last_frame_end_ = end;
    if (faults_.decide_echo()) {
        ++wire_.echoes;
        schedule(Output{settings_.wire_time ? end : now, frame, false});
    }

    // Broadcast: 0 for Modbus and WTEC; the EXCD203MB also listens to 0xFF
    // (002_75205a2c187b1b08.txt, communication settings). The models decide
    // whether they answer; this only feeds the statistics.
    const bool broadcast = attempt.address == 0 ||
                           (attempt.protocol == BusProtocol::modbus_rtu && attempt.address == 0xFF);
    if (broadcast) {
        ++wire_.broadcasts;
    }

    advance(now);
    std::vector<std::pair<Slot*, protocol::Bytes>> replies;
    for (auto& slot : slots_) {
        if (slot.device->protocol() != attempt.protocol) {
            continue;
        }
        const bool addressed = slot.device->address() == attempt.address;
        if (addressed) {
            ++slot.counters.frames;
        }
        if (slot.dead) {
            if (addressed) {
                ++slot.counters.ignored_dead;
            }
            continue;
        }
        auto reply = slot.device->on_frame(frame, now);
        if (reply && !reply->empty()) {
            ++slot.counters.replies;
            replies.emplace_back(&slot, std::move(*reply));
        }
    }
    if (replies.empty() && !broadcast) {
        ++wire_.unanswered;
    }

    // Several replies to one frame (WTEC `$` read all stations) follow each other on
    // the line, each after its own turnaround.
    auto cursor = settings_.wire_time ? end : now;
    for (auto& [slot, bytes] : replies) {
        const auto faults = faults_.decide_reply(slot->device->address());
        if (faults.drop) {
            ++slot->counters.dropped;
            ++wire_.dropped;
            log_->debug("{}: fault drop: reply of {}@{} not sent", settings_.name,
                        slot->device->type(), slot->device->address());
            continue;
        }
        auto out = damage(std::move(bytes), attempt.protocol, faults, slot->counters);
        if (log_->should_log(spdlog::level::trace)) {
            log_->trace("{}: reply {}@{} {}", settings_.name, slot->device->type(), slot->device->address(),
                        hex_bytes(out));
        }
        auto at = cursor + faults.delay;
        if (settings_.wire_time) {
            // A slave knows the request has ended only after 3.5 characters of
            // silence (Modbus over Serial Line V1.02, 2.5.1.1); then it turns the
            // line around and sends. Spec section 9: earliest answer 2.78 ms for a
            // 2-register read at 115200 with 1 ms turnaround.
            at += settings_.timing.silence() + settings_.turnaround +
                  settings_.timing.bytes(out.size());
        }
        cursor = at;
        wire_.busy += settings_.timing.bytes(out.size());
        last_frame_end_ = std::max(*last_frame_end_, at);
        line_free_ = std::max(line_free_, at);
        schedule(Output{at, std::move(out), true});
    }
}

protocol::Bytes BusEngine::damage(protocol::Bytes reply, BusProtocol protocol,
                                  const ReplyFaults& faults, DeviceCounters& counters) {
    if (faults.corrupt_crc && reply.size() >= 2) {
        ++counters.corrupted;
        if (protocol == BusProtocol::modbus_rtu) {
            reply.back() ^= 0xFF;  // CRC high byte (sent last)
        } else {
            // Last CRC digit before CR LF: swap it for another hex digit.
            const auto at = reply.size() >= 3 ? reply.size() - 3 : reply.size() - 1;
            reply[at] = reply[at] == '0' ? '1' : '0';
        }
    }
    if (faults.truncate) {
        ++counters.truncated;
        reply.resize(std::max<std::size_t>(reply.size() / 2, 1));
    }
    if (faults.garbage) {
        ++counters.garbage_injected;
        auto noise = faults_.random_garbage();
        reply.insert(reply.begin(), noise.begin(), noise.end());
    }
    if (faults.delay.count() > 0) {
        ++counters.delayed;
    }
    return reply;
}

// ---- output ---------------------------------------------------------------------

bool BusEngine::reply_pending(Clock::time_point now) const noexcept {
    // A reply due now (no wire time, no delay) is written before the next read: the
    // bytes behind its request in the same burst are the master's next frame.
    return queued_replies_ > 0 && reply_busy_until_ > now;
}

void BusEngine::schedule(Output output) {
    if (output.reply) {
        ++queued_replies_;
        reply_busy_until_ = std::max(reply_busy_until_, output.at);
    }
    const auto pos = std::upper_bound(outputs_.begin(), outputs_.end(), output.at,
                                      [](Clock::time_point t, const Output& o) { return t < o.at; });
    outputs_.insert(pos, std::move(output));
}

std::optional<Clock::time_point> BusEngine::next_output() const {
    if (outputs_.empty()) {
        return std::nullopt;
    }
    return outputs_.front().at;
}

std::vector<BusEngine::Output> BusEngine::take_due(Clock::time_point now) {
    std::vector<Output> due;
    auto it = outputs_.begin();
    while (it != outputs_.end() && it->at <= now) {
        if (it->reply) {
            --queued_replies_;
        }
        due.push_back(std::move(*it));
        ++it;
    }
    outputs_.erase(outputs_.begin(), it);
    return due;
}

void BusEngine::on_written(const Output& output, std::size_t written, Clock::time_point when) {
    wire_.bytes_out += written;
    if (written < output.bytes.size()) {
        wire_.tx_overflow_bytes += output.bytes.size() - written;
    }
    if (output.reply) {
        ++wire_.replies;
    }
    if (settings_.wire_time) {
        wire_.timing.record(std::chrono::duration_cast<std::chrono::nanoseconds>(
            std::max(when - output.at, Clock::duration::zero())));
    }
}

// ---- models, faults, control ----------------------------------------------------

void BusEngine::advance(Clock::time_point now) {
    for (auto& slot : slots_) {
        slot.device->advance(now);
    }
}

void BusEngine::reset_line() {
    rx_.clear();
    rx_end_.clear();
    outputs_.clear();
    queued_replies_ = 0;
    reply_busy_until_ = {};
    last_frame_end_.reset();
    line_free_ = {};
}

BusEngine::Slot* BusEngine::find(std::uint8_t address) noexcept {
    for (auto& slot : slots_) {
        if (slot.device->address() == address) {
            return &slot;
        }
    }
    return nullptr;
}

const BusEngine::Slot* BusEngine::find(std::uint8_t address) const noexcept {
    for (const auto& slot : slots_) {
        if (slot.device->address() == address) {
            return &slot;
        }
    }
    return nullptr;
}

bool BusEngine::has_device(std::uint8_t address) const noexcept { return find(address) != nullptr; }

void BusEngine::apply_fault(const FaultSpec& spec) {
    if (spec.address && !has_device(*spec.address)) {
        throw SimError(fmt::format("fault on {}: no device at address {} on this bus; see "
                                   "`stats` for the addresses",
                                   settings_.name, *spec.address));
    }
    switch (spec.kind) {
        case FaultKind::dead:
        case FaultKind::revive:
            for (auto& slot : slots_) {
                if (!spec.address || slot.device->address() == *spec.address) {
                    slot.dead = spec.kind == FaultKind::dead;
                    log_->info("{}: {}@{} is {}", settings_.name, slot.device->type(),
                               slot.device->address(), slot.dead ? "dead" : "alive again");
                }
            }
            return;
        case FaultKind::unplug:
            throw SimError(fmt::format("fault on {}: unplug is handled by the bus, not the engine",
                                       settings_.name));
        default:
            faults_.set(spec);
            log_->info("{}: fault {} {} on {}", settings_.name, to_string(spec.kind),
                       spec.trigger.mode == FaultTrigger::Mode::off ? "removed" : "set",
                       spec.address ? fmt::format("device {}", *spec.address) : "the whole bus");
            return;
    }
}

void BusEngine::clear_faults(std::optional<std::uint8_t> address) {
    faults_.clear(address);
    for (auto& slot : slots_) {
        if (!address || slot.device->address() == *address) {
            slot.dead = false;
        }
    }
}

std::string BusEngine::device_control(std::uint8_t address, std::string_view command,
                                      Clock::time_point now) {
    auto* slot = find(address);
    if (slot == nullptr) {
        return fmt::format("no device at address {} on {}", address, settings_.name);
    }
    slot->device->advance(now);
    return slot->device->control(command, now);
}

nlohmann::json BusEngine::stats(Clock::time_point now) const {
    auto json = to_json(wire_);
    const auto elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(now - started_);
    json["utilization"] = elapsed.count() > 0 ? static_cast<double>(wire_.busy.count()) /
                                                    static_cast<double>(elapsed.count())
                                              : 0.0;
    json["baud"] = settings_.timing.baud;
    json["bits_per_character"] = settings_.timing.bits_per_character;
    json["wire_time"] = settings_.wire_time;
    json["turnaround_us"] = static_cast<double>(settings_.turnaround.count()) / 1e3;
    json["silence_us"] = static_cast<double>(settings_.timing.silence().count()) / 1e3;
    json["faults"] = faults_.describe();
    auto devices = nlohmann::json::object();
    for (const auto& slot : slots_) {
        auto entry = to_json(slot.counters);
        entry["type"] = slot.device->type();
        entry["dead"] = slot.dead;
        devices[std::to_string(slot.device->address())] = std::move(entry);
    }
    json["devices"] = std::move(devices);
    return json;
}

}  // namespace fieldbridge::sim::runtime
