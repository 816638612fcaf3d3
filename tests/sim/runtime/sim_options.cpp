#include "sim_options.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <fmt/format.h>
#include <set>

#include "durations.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

constexpr std::string_view footer = R"(
BUS SPEC (--bus, repeatable)
  PATH:TYPE@ADDR[/KEY=VALUE...][,TYPE@ADDR...]
  TYPE: hiwin-xeg | excd203mb | wtec-rtu | wtec-ascii | modbus, or the name of a
  device definition (see DEFINITIONS). Modbus-RTU and WTEC ASCII
  devices may share a bus: a frame starting with '>' is ASCII, anything else RTU.
  Per-device keys: model=0x0A20 (hiwin-xeg), stroke=20000 (wtec-*),
  word-order=high_first|low_first (excd203mb).
  The pty's slave side is linked at PATH (directory created, stale link replaced,
  link removed on exit); the bus is named after the file name (line-a).
  e.g. --bus /tmp/x/line-a:hiwin-xeg@2,excd203mb@3,wtec-ascii@5 --bus /tmp/x/line-b:wtec-rtu@1

DEFINITIONS (--definitions DIR, --definition FILE, both repeatable)
  A TYPE that is not built in names a device definition (docs/devices.md): a
  --definition FILE named TYPE.yaml, else TYPE.yaml in the first --definitions DIR
  that has one. The device has exactly the registers and coils of the definition's
  points and blocks (02 elsewhere), all 0 at start; control commands
  "device ADDR set POINT VALUE" (engineering units, enum label, true/false, text)
  and "device ADDR set-register TABLE ADDRESS VALUE..." change them.
  e.g. --definitions config/devices --bus /tmp/x/line-a:thermostat-example@7

WIRE TIME (--wire-time)
  A pty moves bytes instantly; with --wire-time the simulator delivers each reply
  when a real line would have: request end + 3.5 x tc (end-of-frame silence) +
  turnaround + reply bytes x tc, with tc = (10, or 11 with parity or 2 stop
  bits) / baud; e.g. a 2-register read at 115200 with 1 ms turnaround is answered
  2.78 ms after the request started. The master's silence before each request
  is checked against 3.5 x tc (gap_violations); bytes sent while a reply is
  pending are a collision and are discarded. Without --wire-time replies are
  immediate and --turnaround is not used.

FAULTS (--fault, repeatable; control socket: fault ...)
  BUS[@ADDR]:KIND[:MS][:WHEN]
  KIND: drop | corrupt-crc | truncate | delay:MS | garbage  (reply faults)
        echo (bus-wide: requests echoed back, like a 2-wire adapter)
        dead | revive (device state) | unplug:MS (pty vanishes for MS, link too)
  WHEN: always (default) | P (probability 0<P<=1) | next=N | off
  e.g. line-a:drop:0.01  line-a@2:delay:50:next=3  line-a:echo  line-a@3:dead
  Randomness is reproducible with --seed.

CONTROL SOCKET (--control PATH, UNIX stream socket, one line in, one line out)
  stats                          counters as JSON ("ok {...}")
  device [BUS@]ADDR COMMAND...   forwards to the device model, e.g. device 2 alarm 7
  fault SPEC | fault clear [BUS[@ADDR]]
  r6 COMMAND...                  forwards to the R6 model
  help
  Replies: "ok", "ok <data>" or "error: <what went wrong>".

R6 (--r6 HOST:PORT)
  Modbus TCP slave on loopback simulating a Huacheng R6 controller. Every unit id is
  answered, like the controller; --r6-unit N answers only unit N and gives other
  units exception 0x0B.

OUTPUT
  "READY" on stdout once every pty, socket and listener is up; logs on stderr.
  SIGINT/SIGTERM or --duration: clean exit 0, links and sockets removed, final
  stats written.)";

std::uint8_t parse_u8(std::string_view text, std::string_view what) {
    unsigned value = 0;
    int base = 10;
    if (text.starts_with("0x") || text.starts_with("0X")) {
        text.remove_prefix(2);
        base = 16;
    }
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() || value > 255) {
        throw SimError(fmt::format("{}: '{}' is not a number 0-255", what, text));
    }
    return static_cast<std::uint8_t>(value);
}

std::uint32_t parse_u32(std::string_view text, std::string_view what) {
    std::uint32_t value = 0;
    int base = 10;
    if (text.starts_with("0x") || text.starts_with("0X")) {
        text.remove_prefix(2);
        base = 16;
    }
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size()) {
        throw SimError(fmt::format("{}: '{}' is not a whole number", what, text));
    }
    return value;
}

std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    while (true) {
        const auto at = text.find(separator, start);
        parts.push_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
        if (at == std::string_view::npos) {
            return parts;
        }
        start = at + 1;
    }
}

DeviceSpec parse_device(std::string_view text, std::string_view bus, const DeviceOptions& defaults) {
    const auto what = fmt::format("--bus {}: device '{}'", bus, text);
    auto parts = split(text, '/');
    const auto head = parts[0];
    const auto at = head.find('@');
    if (at == std::string_view::npos || at == 0) {
        throw SimError(fmt::format("{}: expected TYPE@ADDRESS, e.g. hiwin-xeg@2", what));
    }
    DeviceSpec device;
    device.type = std::string(head.substr(0, at));
    device.address = parse_u8(head.substr(at + 1), what);
    device.options = defaults;
    for (std::size_t i = 1; i < parts.size(); ++i) {
        const auto eq = parts[i].find('=');
        if (eq == std::string_view::npos) {
            throw SimError(fmt::format("{}: option '{}' is not KEY=VALUE", what, parts[i]));
        }
        const auto key = parts[i].substr(0, eq);
        const auto value = parts[i].substr(eq + 1);
        if (key == "model") {
            const auto model = parse_u32(value, what);
            if (model > 0xFFFF) {
                throw SimError(fmt::format("{}: model {} is above 0xFFFF", what, value));
            }
            device.options.xeg_model = static_cast<std::uint16_t>(model);
        } else if (key == "stroke") {
            device.options.wtec_stroke = parse_u32(value, what);
        } else if (key == "word-order") {
            device.options.excd_word_order = std::string(value);
        } else {
            throw SimError(fmt::format("{}: unknown option '{}'; use model=, stroke= or word-order=",
                                       what, key));
        }
    }
    return device;
}

}  // namespace

void add_options(CLI::App& app, RawOptions& raw) {
    app.description(
        "fieldbridge-sim: simulated HIWIN XEG-C2, EXCD203MB and WTEC-485 devices on "
        "pseudo-terminal RS-485 buses (optional wire-time emulation and fault injection) "
        "and a Huacheng R6 Modbus TCP simulator on loopback.");
    app.add_option("--bus", raw.buses, "A bus: PATH:TYPE@ADDR[,TYPE@ADDR...] (repeatable; see BUS SPEC)");
    app.add_option("--r6", raw.r6, "Run the R6 Modbus TCP simulator on HOST:PORT (e.g. 127.0.0.1:15020; port 0 picks one)");
    app.add_option("--r6-unit", raw.r6_unit, "Answer only this unit id (others get exception 0x0B); default: every unit")
        ->check(CLI::Range(0, 255));
    app.add_flag("--wire-time", raw.wire_time, "Emulate wire time: deliver replies when a real line would");
    app.add_option("--baud", raw.baud, "Line speed for wire time and silence checks")
        ->capture_default_str()->check(CLI::Range(300u, 4000000u));
    app.add_option("--parity", raw.parity, "N, E or O (E/O make a character 11 bits)")->capture_default_str();
    app.add_option("--stop-bits", raw.stop_bits, "1 or 2")->capture_default_str()->check(CLI::Range(1u, 2u));
    app.add_option("--turnaround", raw.turnaround, "Device turnaround before a reply (wire time only), e.g. 1ms, 500us")
        ->capture_default_str();
    app.add_option("--tick", raw.tick, "How often the device models advance their motion")->capture_default_str();
    app.add_option("--duration", raw.duration, "Stop by itself after this long (e.g. 60s; bare number = seconds)");
    app.add_option("--control", raw.control, "UNIX socket for control commands (see CONTROL SOCKET)");
    app.add_option("--stats-file", raw.stats_file, "Write counters as JSON here every second and at exit");
    app.add_option("--seed", raw.seed, "Seed for fault randomness (default: random, logged)");
    app.add_option("--fault", raw.faults, "Inject a fault from the start (repeatable; see FAULTS)");
    app.add_option("--xeg-model", raw.xeg_model, "Default gripper model code of hiwin-xeg devices (register 0x0600)")
        ->capture_default_str();
    app.add_option("--wtec-stroke", raw.wtec_stroke, "Default full stroke of wtec-* devices, encoder counts")
        ->capture_default_str();
    app.add_option("--excd-word-order", raw.excd_word_order, "Default 32-bit word order of excd203mb devices: high_first or low_first")
        ->capture_default_str();
    app.add_option("--definitions", raw.definition_dirs,
                   "A directory of device definition files NAME.yaml (repeatable; the first that has a name wins)");
    app.add_option("--definition", raw.definition_files, "A device definition file NAME.yaml (repeatable)");
    app.add_option("--log-level", raw.log_level, "trace, debug, info, warn, error")->capture_default_str();
    app.footer(std::string(footer));
}

Endpoint parse_endpoint(std::string_view text, std::string_view what) {
    const auto colon = text.rfind(':');
    if (colon == std::string_view::npos || colon == 0) {
        throw SimError(fmt::format("{}: '{}' is not HOST:PORT (e.g. 127.0.0.1:15020)", what, text));
    }
    Endpoint endpoint;
    auto host = text.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
        host = host.substr(1, host.size() - 2);
    }
    endpoint.host = std::string(host);
    const auto port_text = text.substr(colon + 1);
    unsigned port = 0;
    const auto [ptr, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
    if (port_text.empty() || ec != std::errc{} || ptr != port_text.data() + port_text.size() || port > 65535) {
        throw SimError(fmt::format("{}: port '{}' is not 0-65535", what, port_text));
    }
    endpoint.port = static_cast<std::uint16_t>(port);
    return endpoint;
}

BusSpec parse_bus_spec(std::string_view text, const DeviceOptions& defaults) {
    const auto colon = text.rfind(':');
    if (colon == std::string_view::npos || colon == 0 || colon + 1 == text.size()) {
        throw SimError(fmt::format("--bus '{}': expected PATH:TYPE@ADDR[,TYPE@ADDR...], e.g. "
                                   "/tmp/x/line-a:hiwin-xeg@2,wtec-ascii@5",
                                   text));
    }
    BusSpec bus;
    bus.link = std::filesystem::path(std::string(text.substr(0, colon)));
    bus.name = bus.link.filename().string();
    if (bus.name.empty() || bus.name.find('@') != std::string::npos) {
        throw SimError(fmt::format("--bus '{}': the path must end in a file name without '@' "
                                   "(it names the bus)",
                                   text));
    }
    std::set<std::uint8_t> addresses;
    for (const auto item : split(text.substr(colon + 1), ',')) {
        auto device = parse_device(item, bus.name, defaults);
        if (!addresses.insert(device.address).second) {
            throw SimError(fmt::format("--bus {}: two devices at address {}; give each device on "
                                       "a bus its own address",
                                       bus.name, device.address));
        }
        bus.devices.push_back(std::move(device));
    }
    return bus;
}

SimOptions build_options(const RawOptions& raw) {
    SimOptions options;
    DeviceOptions defaults;
    const auto model = parse_u32(raw.xeg_model, "--xeg-model");
    if (model > 0xFFFF) {
        throw SimError(fmt::format("--xeg-model: {} is above 0xFFFF", raw.xeg_model));
    }
    defaults.xeg_model = static_cast<std::uint16_t>(model);
    defaults.wtec_stroke = raw.wtec_stroke;
    defaults.excd_word_order = raw.excd_word_order;

    std::set<std::string> names;
    for (const auto& text : raw.buses) {
        auto bus = parse_bus_spec(text, defaults);
        if (!names.insert(bus.name).second) {
            throw SimError(fmt::format("--bus: two buses are named {}; bus names come from the "
                                       "link's file name and must differ",
                                       bus.name));
        }
        options.buses.push_back(std::move(bus));
    }
    attach_definitions(options.buses, raw.definition_dirs, raw.definition_files);
    if (!raw.r6.empty()) {
        options.r6 = parse_endpoint(raw.r6, "--r6");
    }
    if (raw.r6_unit >= 0) {
        options.r6_unit = static_cast<std::uint8_t>(raw.r6_unit);
    }
    if (options.buses.empty() && !options.r6) {
        throw SimError("nothing to simulate: give at least one --bus or --r6 (see --help)");
    }
    options.wire_time = raw.wire_time;
    options.baud = raw.baud;
    if (raw.parity.size() != 1 || std::string_view("NEOneo").find(raw.parity[0]) == std::string_view::npos) {
        throw SimError(fmt::format("--parity: '{}' is not N, E or O", raw.parity));
    }
    options.parity = static_cast<char>(std::toupper(static_cast<unsigned char>(raw.parity[0])));
    options.stop_bits = raw.stop_bits;
    options.turnaround = std::chrono::duration_cast<std::chrono::nanoseconds>(
        parse_duration(raw.turnaround, DefaultUnit::milliseconds, "--turnaround"));
    options.tick = std::chrono::duration_cast<std::chrono::nanoseconds>(
        parse_duration(raw.tick, DefaultUnit::milliseconds, "--tick"));
    if (options.tick < std::chrono::milliseconds(1)) {
        throw SimError("--tick: must be at least 1ms");
    }
    if (!raw.duration.empty()) {
        options.duration = std::chrono::duration_cast<std::chrono::nanoseconds>(
            parse_duration(raw.duration, DefaultUnit::seconds, "--duration"));
    }
    if (!raw.control.empty()) {
        options.control = raw.control;
    }
    if (!raw.stats_file.empty()) {
        options.stats_file = raw.stats_file;
    }
    if (!raw.seed.empty()) {
        std::uint64_t seed = 0;
        const auto [ptr, ec] = std::from_chars(raw.seed.data(), raw.seed.data() + raw.seed.size(), seed);
        if (ec != std::errc{} || ptr != raw.seed.data() + raw.seed.size()) {
            throw SimError(fmt::format("--seed: '{}' is not a whole number", raw.seed));
        }
        options.seed = seed;
    }
    for (const auto& text : raw.faults) {
        auto spec = parse_fault_spec(text);
        if (!names.contains(spec.bus)) {
            throw SimError(fmt::format("--fault {}: no bus named {} (buses are named after their "
                                       "link's file name)",
                                       text, spec.bus));
        }
        options.faults.push_back(std::move(spec));
    }
    constexpr std::array<std::string_view, 6> levels{"trace", "debug", "info", "warn", "error", "off"};
    if (std::find(levels.begin(), levels.end(), raw.log_level) == levels.end()) {
        throw SimError(fmt::format("--log-level: '{}' is not trace, debug, info, warn, error or off",
                                   raw.log_level));
    }
    options.log_level = raw.log_level;
    return options;
}

}  // namespace fieldbridge::sim::runtime
