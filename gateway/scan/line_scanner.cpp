#include "scan/line_scanner.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <variant>

#include "protocol/wtec_ascii_commands.hpp"

namespace fieldbridge::scan {

namespace {

namespace wtec = protocol::wtec;

/// How long after the first `$` reply other stations may still be answering: a
/// reply is 14 characters (about 1.2 ms at 115200 bit/s), so this is generous.
constexpr auto more_stations_limit = std::chrono::milliseconds{500};

/// Addresses between progress lines during the Modbus sweep.
constexpr unsigned progress_every = 50;

[[nodiscard]] std::string describe(const FoundDevice& d) {
    return "address " + std::to_string(d.address) + ": " +
           (d.definition.empty() ? std::string{engine::to_string(d.type)} : d.definition) + ", " + d.detail;
}

}  // namespace

LineScanner::LineScanner(LineLink& link, ScanRange range, Progress progress,
                         std::vector<DefinitionIdentify> definitions)
    : link_(link), range_(range), progress_(std::move(progress)), definitions_(std::move(definitions)) {}

void LineScanner::report(const std::string& text) const {
    if (progress_) {
        progress_(text);
    }
}

engine::Outcome LineScanner::send(engine::Payload payload, std::uint8_t address, ScanStats& stats,
                                  protocol::Bytes* received) {
    engine::Outcome outcome = link_.transact(std::move(payload), address, received);
    ++stats.requests;
    if (outcome.status != engine::OutcomeStatus::ok) {
        ++stats.timeouts;
    }
    return outcome;
}

std::vector<FoundDevice> LineScanner::find_ascii_stations(ScanStats& stats) {
    // Seed 003 command 2: `$` to 00 is answered by every ASCII device from its own
    // address. RTU devices drop the frame: '>' (0x3E) is read as an address and the
    // CRC does not match.
    protocol::Bytes received;
    const engine::Outcome first =
        send(engine::AsciiPayload{wtec::ReadStations{}}, wtec::broadcast_address, stats, &received);
    std::vector<std::uint8_t> stations;
    if (first.status == engine::OutcomeStatus::ok) {
        // The line master hands out the first reply and drops what came with it; the
        // other stations' replies are in the bytes received then and right after.
        const auto quiet = link_.master().config().ascii_frame_timeout;
        const protocol::Bytes rest = link_.listen(quiet, more_stations_limit);
        received.insert(received.end(), rest.begin(), rest.end());
        stations = parse_stations(received);
    }
    std::vector<FoundDevice> found;
    for (const std::uint8_t address : stations) {
        if (address < range_.first || address > range_.last) {
            report("WTEC ASCII station " + std::to_string(address) + " answered `$` but is outside the range " +
                   std::to_string(range_.first) + "-" + std::to_string(range_.last) + "; not listed");
            continue;
        }
        // Confirm with a request addressed to the station alone (a `$` reply can be
        // the only survivor of a collision) and read its firmware text.
        FoundDevice device{address, engine::DeviceType::wtec_ascii, "answers `$`, but not `A` (read version)", false, {}};
        const engine::Outcome version = send(engine::AsciiPayload{wtec::ReadVersion{}}, address, stats);
        if (const auto* reply = std::get_if<wtec::Reply>(&version.reply)) {
            if (const auto* text = std::get_if<wtec::Version>(reply)) {
                device.detail = "firmware \"" + text->text + "\"";
            }
        }
        report(describe(device));
        found.push_back(std::move(device));
    }
    return found;
}

std::optional<FoundDevice> LineScanner::probe_modbus(std::uint8_t address, ScanStats& stats) {
    ModbusProbe probe(address, definitions_);
    while (const auto request = probe.next()) {
        const engine::Outcome outcome = send(engine::ModbusPayload{*request}, address, stats);
        const auto* response = std::get_if<protocol::Response>(&outcome.reply);
        probe.on_reply(outcome.status == engine::OutcomeStatus::ok && response != nullptr
                           ? std::optional<protocol::Response>{*response}
                           : std::nullopt);
    }
    return probe.result();
}

ScanResult LineScanner::run() {
    ScanResult result;
    const auto start = engine::Clock::now();
    result.devices = find_ascii_stations(result.stats);
    const auto is_ascii = [&result](std::uint8_t address) {
        return std::any_of(result.devices.begin(), result.devices.end(),
                           [address](const FoundDevice& d) { return d.address == address; });
    };
    unsigned probed = 0;
    for (unsigned a = range_.first; a <= range_.last; ++a) {
        const auto address = static_cast<std::uint8_t>(a);
        if (!is_ascii(address)) {
            if (auto device = probe_modbus(address, result.stats)) {
                report(describe(*device));
                result.devices.push_back(std::move(*device));
            }
        }
        if (++probed % progress_every == 0 && a < range_.last) {
            report("... Modbus probe at address " + std::to_string(a) + " of " + std::to_string(range_.first) + "-" +
                   std::to_string(range_.last));
        }
    }
    std::sort(result.devices.begin(), result.devices.end(),
              [](const FoundDevice& x, const FoundDevice& y) { return x.address < y.address; });
    result.stats.elapsed = engine::Clock::now() - start;
    return result;
}

}  // namespace fieldbridge::scan
