#include "fault_plan.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <fmt/format.h>

#include "durations.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

constexpr std::string_view grammar =
    "expected BUS[@ADDRESS]:KIND[:MS][:WHEN] with KIND one of drop, corrupt-crc, truncate, "
    "delay:MS, garbage, echo, dead, revive, unplug:MS and WHEN one of always, a probability "
    "0<P<=1, next=N, off (e.g. line-a@2:drop:0.1, line-a:delay:20:next=3, line-a:unplug:500)";

struct KindName {
    std::string_view name;
    FaultKind kind;
};
constexpr std::array<KindName, 9> kind_names{{
    {"drop", FaultKind::drop},
    {"corrupt-crc", FaultKind::corrupt_crc},
    {"truncate", FaultKind::truncate},
    {"delay", FaultKind::delay},
    {"garbage", FaultKind::garbage},
    {"echo", FaultKind::echo},
    {"dead", FaultKind::dead},
    {"revive", FaultKind::revive},
    {"unplug", FaultKind::unplug},
}};

std::vector<std::string_view> split_fields(std::string_view text) {
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i) {
        if (i == text.size() || text[i] == ':' || text[i] == ' ' || text[i] == '\t') {
            if (i > start) {
                fields.push_back(text.substr(start, i - start));
            }
            start = i + 1;
        }
    }
    return fields;
}

std::uint8_t parse_address(std::string_view text, std::string_view spec) {
    unsigned value = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || ptr != text.data() + text.size() || value > 255) {
        throw SimError(fmt::format("fault '{}': device address '{}' is not a number 0-255; {}",
                                   spec, text, grammar));
    }
    return static_cast<std::uint8_t>(value);
}

FaultTrigger parse_trigger(std::string_view text, std::string_view spec) {
    FaultTrigger trigger;
    if (text == "always" || text == "on") {
        return trigger;
    }
    if (text == "off") {
        trigger.mode = FaultTrigger::Mode::off;
        return trigger;
    }
    if (text.starts_with("next=")) {
        const auto digits = text.substr(5);
        std::uint64_t count = 0;
        const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), count);
        if (ec != std::errc{} || ptr != digits.data() + digits.size() || count == 0) {
            throw SimError(fmt::format("fault '{}': '{}' needs a whole count >= 1 after next=; {}",
                                       spec, text, grammar));
        }
        trigger.mode = FaultTrigger::Mode::next;
        trigger.remaining = count;
        return trigger;
    }
    double p = 0.0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), p);
    if (ec != std::errc{} || ptr != text.data() + text.size() || !(p > 0.0) || p > 1.0) {
        throw SimError(fmt::format("fault '{}': '{}' is not a trigger; {}", spec, text, grammar));
    }
    trigger.mode = p >= 1.0 ? FaultTrigger::Mode::always : FaultTrigger::Mode::probability;
    trigger.probability = p;
    return trigger;
}

}  // namespace

std::string_view to_string(FaultKind kind) noexcept {
    for (const auto& entry : kind_names) {
        if (entry.kind == kind) {
            return entry.name;
        }
    }
    return "unknown";
}

FaultSpec parse_fault_spec(std::string_view text) {
    const auto fields = split_fields(text);
    if (fields.size() < 2) {
        throw SimError(fmt::format("fault '{}': too few fields; {}", text, grammar));
    }
    FaultSpec spec;
    const auto target = fields[0];
    if (const auto at = target.find('@'); at != std::string_view::npos) {
        spec.bus = std::string(target.substr(0, at));
        spec.address = parse_address(target.substr(at + 1), text);
    } else {
        spec.bus = std::string(target);
    }
    if (spec.bus.empty()) {
        throw SimError(fmt::format("fault '{}': no bus name; {}", text, grammar));
    }
    const auto kind = std::find_if(kind_names.begin(), kind_names.end(),
                                   [&](const KindName& k) { return k.name == fields[1]; });
    if (kind == kind_names.end()) {
        throw SimError(fmt::format("fault '{}': unknown fault kind '{}'; {}", text, fields[1], grammar));
    }
    spec.kind = kind->kind;
    std::size_t next = 2;
    const bool removing = fields.size() == next + 1 && fields[next] == "off";
    if ((spec.kind == FaultKind::delay || spec.kind == FaultKind::unplug) && !removing) {
        if (fields.size() <= next) {
            throw SimError(fmt::format("fault '{}': {} needs a duration in ms; {}", text,
                                       kind->name, grammar));
        }
        spec.duration = std::chrono::duration_cast<std::chrono::nanoseconds>(
            parse_duration(fields[next], DefaultUnit::milliseconds, "fault duration"));
        ++next;
    }
    if (fields.size() > next) {
        spec.trigger = parse_trigger(fields[next], text);
        ++next;
    }
    if (fields.size() > next) {
        throw SimError(fmt::format("fault '{}': unexpected '{}' at the end; {}", text, fields[next],
                                   grammar));
    }
    const bool action = spec.kind == FaultKind::dead || spec.kind == FaultKind::revive ||
                        spec.kind == FaultKind::unplug;
    if (action && spec.trigger != FaultTrigger{}) {
        throw SimError(fmt::format("fault '{}': {} is an action and takes no trigger", text,
                                   kind->name));
    }
    if ((spec.kind == FaultKind::echo || spec.kind == FaultKind::unplug) && spec.address) {
        throw SimError(fmt::format("fault '{}': {} is bus-wide; name the bus without @address",
                                   text, kind->name));
    }
    return spec;
}

void FaultPlan::set(const FaultSpec& spec) {
    std::erase_if(rules_, [&](const Rule& r) { return r.address == spec.address && r.kind == spec.kind; });
    if (spec.trigger.mode == FaultTrigger::Mode::off) {
        return;
    }
    rules_.push_back(Rule{spec.address, spec.kind, spec.duration, spec.trigger});
}

void FaultPlan::clear(std::optional<std::uint8_t> address) {
    if (!address) {
        rules_.clear();
        return;
    }
    std::erase_if(rules_, [&](const Rule& r) { return r.address == address; });
}

bool FaultPlan::fire(Rule& rule) {
    switch (rule.trigger.mode) {
        case FaultTrigger::Mode::always: return true;
        case FaultTrigger::Mode::off: return false;
        case FaultTrigger::Mode::probability: {
            std::uniform_real_distribution<double> draw(0.0, 1.0);
            return draw(rng_) < rule.trigger.probability;
        }
        case FaultTrigger::Mode::next:
            if (rule.trigger.remaining == 0) {
                return false;
            }
            --rule.trigger.remaining;
            return true;
    }
    return false;
}

ReplyFaults FaultPlan::decide_reply(std::uint8_t address) {
    ReplyFaults faults;
    for (auto& rule : rules_) {
        if (rule.kind == FaultKind::echo || (rule.address && *rule.address != address)) {
            continue;
        }
        if (!fire(rule)) {
            continue;
        }
        switch (rule.kind) {
            case FaultKind::drop: faults.drop = true; break;
            case FaultKind::corrupt_crc: faults.corrupt_crc = true; break;
            case FaultKind::truncate: faults.truncate = true; break;
            case FaultKind::garbage: faults.garbage = true; break;
            case FaultKind::delay: faults.delay += rule.duration; break;
            default: break;
        }
    }
    std::erase_if(rules_, [](const Rule& r) {
        return r.trigger.mode == FaultTrigger::Mode::next && r.trigger.remaining == 0;
    });
    return faults;
}

bool FaultPlan::decide_echo() {
    bool echo = false;
    for (auto& rule : rules_) {
        if (rule.kind == FaultKind::echo && fire(rule)) {
            echo = true;
        }
    }
    std::erase_if(rules_, [](const Rule& r) {
        return r.trigger.mode == FaultTrigger::Mode::next && r.trigger.remaining == 0;
    });
    return echo;
}

protocol::Bytes FaultPlan::random_garbage() {
    std::uniform_int_distribution<unsigned> length(1, 8);
    std::uniform_int_distribution<unsigned> value(0, 254);
    protocol::Bytes bytes(length(rng_));
    for (auto& b : bytes) {
        const auto v = value(rng_);
        // '>' would start a WTEC ASCII frame and swallow the real reply behind it.
        b = static_cast<std::uint8_t>(v >= '>' ? v + 1 : v);
    }
    return bytes;
}

nlohmann::json FaultPlan::describe() const {
    auto list = nlohmann::json::array();
    for (const auto& rule : rules_) {
        nlohmann::json item{{"kind", to_string(rule.kind)}};
        item["device"] = rule.address ? nlohmann::json(*rule.address) : nlohmann::json("all");
        if (rule.kind == FaultKind::delay) {
            item["ms"] = static_cast<double>(rule.duration.count()) / 1e6;
        }
        switch (rule.trigger.mode) {
            case FaultTrigger::Mode::always: item["when"] = "always"; break;
            case FaultTrigger::Mode::probability: item["when"] = rule.trigger.probability; break;
            case FaultTrigger::Mode::next:
                item["when"] = fmt::format("next={}", rule.trigger.remaining);
                break;
            case FaultTrigger::Mode::off: item["when"] = "off"; break;
        }
        list.push_back(std::move(item));
    }
    return list;
}

}  // namespace fieldbridge::sim::runtime
