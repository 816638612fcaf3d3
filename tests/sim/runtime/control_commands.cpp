// The control language of fieldbridge-sim (Simulator::command): one text line in,
// one line out, "ok [data]" or "error: what went wrong".
#include <charconv>
#include <fmt/format.h>

#include "models/r6_model.hpp"
#include "sim_error.hpp"
#include "simulator.hpp"

namespace fieldbridge::sim::runtime {
namespace {

constexpr std::string_view help_text =
    "ok commands: stats | device [BUS@]ADDR COMMAND... | fault BUS[@ADDR]:KIND[:MS][:WHEN] | "
    "fault clear [BUS[@ADDR]] | silence BUS | r6 COMMAND... | help";

std::string_view trim(std::string_view text) {
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) {
        text.remove_prefix(1);
    }
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) {
        text.remove_suffix(1);
    }
    return text;
}

/// Splits "word rest of line" into the first word and the trimmed rest.
std::pair<std::string_view, std::string_view> first_word(std::string_view text) {
    text = trim(text);
    const auto space = text.find_first_of(" \t");
    if (space == std::string_view::npos) {
        return {text, {}};
    }
    return {text.substr(0, space), trim(text.substr(space + 1))};
}

std::uint8_t parse_address(std::string_view text) {
    unsigned value = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() || value > 255) {
        throw SimError(fmt::format("'{}' is not a device address 0-255", text));
    }
    return static_cast<std::uint8_t>(value);
}

std::string reply(std::string_view error_text) {
    return error_text.empty() ? std::string("ok") : fmt::format("error: {}", error_text);
}

}  // namespace

std::string Simulator::command(std::string_view line) {
    const auto [verb, args] = first_word(line);
    try {
        if (verb == "stats") {
            return "ok " + stats().dump();
        }
        if (verb == "device") {
            return command_device(args);
        }
        if (verb == "fault") {
            return command_fault(args);
        }
        if (verb == "r6") {
            return command_r6(args);
        }
        if (verb == "silence") {
            if (args.empty()) throw SimError("usage: silence BUS, e.g. silence line-a");
            return "ok " + bus_named(args).engine().take_silence_window().dump();
        }
        if (verb == "help" || verb.empty()) {
            return std::string(help_text);
        }
        return fmt::format("error: unknown command '{}'; {}", verb, help_text.substr(3));
    } catch (const SimError& e) {
        return fmt::format("error: {}", e.what());
    }
}

std::string Simulator::command_device(std::string_view args) {
    const auto [target, device_command] = first_word(args);
    if (target.empty() || device_command.empty()) {
        throw SimError("usage: device [BUS@]ADDRESS COMMAND..., e.g. device 2 alarm 7");
    }
    PtyBus* bus = nullptr;
    std::uint8_t address = 0;
    if (const auto at = target.find('@'); at != std::string_view::npos) {
        bus = &bus_named(target.substr(0, at));
        address = parse_address(target.substr(at + 1));
    } else {
        address = parse_address(target);
        for (auto& candidate : buses_) {
            if (!candidate->engine().has_device(address)) {
                continue;
            }
            if (bus != nullptr) {
                throw SimError(fmt::format("address {} is on {} and {}; write BUS@ADDRESS", address,
                                           bus->name(), candidate->name()));
            }
            bus = candidate.get();
        }
        if (bus == nullptr) {
            throw SimError(fmt::format("no device at address {} on any bus", address));
        }
    }
    const auto error = bus->engine().device_control(address, device_command, Clock::now());
    if (error.empty()) {
        log_->info("control: {}@{}: {}", bus->name(), address, device_command);
    }
    return reply(error);
}

std::string Simulator::command_fault(std::string_view args) {
    const auto [first, rest] = first_word(args);
    if (first == "clear") {
        const auto target = trim(rest);
        if (target.empty()) {
            for (auto& bus : buses_) {
                bus->engine().clear_faults(std::nullopt);
            }
            log_->info("control: every fault cleared");
            return "ok";
        }
        const auto at = target.find('@');
        auto& bus = bus_named(target.substr(0, at));
        std::optional<std::uint8_t> address;
        if (at != std::string_view::npos) {
            address = parse_address(target.substr(at + 1));
        }
        bus.engine().clear_faults(address);
        log_->info("control: faults cleared on {}", target);
        return "ok";
    }
    const auto spec = parse_fault_spec(args);
    bus_named(spec.bus).apply_fault(spec);
    return "ok";
}

std::string Simulator::command_r6(std::string_view args) {
    if (!r6_model_) {
        throw SimError("no R6 simulator in this process (start with --r6 HOST:PORT)");
    }
    if (trim(args).empty()) {
        throw SimError("usage: r6 COMMAND...");
    }
    const auto error = r6_model_->control(trim(args), Clock::now());
    if (error.empty()) {
        log_->info("control: r6: {}", trim(args));
    }
    return reply(error);
}

}  // namespace fieldbridge::sim::runtime
