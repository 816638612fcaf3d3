#include "models/excd_model.hpp"

#include <stdexcept>

#include "models/control_words.hpp"
#include "models/modbus_request.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;
namespace fc = protocol::fc;

constexpr std::uint16_t version = 120;  // protocol V1.2 (seed 002 title)

bool signed_range(const ExcdRegister& entry) noexcept { return entry.min < 0; }

bool is_stop(std::string_view name) noexcept {
    return name == "stop" || name == "mstop" || name == "jogstop";
}

}  // namespace

ExcdModel::ExcdModel(std::uint8_t address, ExcdOptions options)
    : address_(address), high_word_first_(options.high_word_first) {
    // seed 002 section 5: device addresses 1-254, 0xFF is broadcast.
    if (address < 1 || address > 254) {
        throw std::invalid_argument("excd203mb: address " + std::to_string(address) +
                                    " is outside 1-254 (0xFF is the broadcast address)");
    }
    for (const auto& entry : table_.entries()) stored_.push_back(entry.initial);
    counts_.assign(51, 0);
}

std::optional<protocol::Bytes> ExcdModel::on_frame(protocol::ByteView frame, Clock::time_point now) {
    const auto request = accept_rtu(frame, address_, protocol::excd_broadcast_address);
    if (!request) return std::nullopt;
    advance(now);
    const std::uint8_t function = request->pdu[0];
    // seed 002 section 2: only 0x03, 0x06 and 0x10 are supported.
    if (function != fc::read_holding_registers && function != fc::write_single_register &&
        function != fc::write_multiple_registers) {
        return rtu_reply(*request, address_, exception_of(function, ExceptionCode::illegal_function));
    }
    auto decoded = decode_or_exception(request->pdu);
    if (auto* error = std::get_if<protocol::Response>(&decoded)) {
        return rtu_reply(*request, address_, *error);
    }
    return rtu_reply(*request, address_, handle(std::get<protocol::Request>(decoded), now));
}

protocol::Response ExcdModel::handle(const protocol::Request& request, Clock::time_point now) {
    if (const auto* read_request = std::get_if<protocol::ReadRegistersRequest>(&request)) {
        return read(*read_request);
    }
    if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        if (const auto error = write(single->address, {single->value}, now)) {
            return exception_of(fc::write_single_register, *error);
        }
        return protocol::WriteSingleResponse{fc::write_single_register, single->address, single->value};
    }
    const auto& multiple = std::get<protocol::WriteMultipleRegistersRequest>(request);
    if (const auto error = write(multiple.address, multiple.values, now)) {
        return exception_of(fc::write_multiple_registers, *error);
    }
    return protocol::WriteMultipleResponse{fc::write_multiple_registers, multiple.address,
                                           static_cast<std::uint16_t>(multiple.values.size())};
}

protocol::Response ExcdModel::read(const protocol::ReadRegistersRequest& request) const {
    protocol::ReadRegistersResponse response{fc::read_holding_registers, {}};
    for (std::uint32_t a = request.address; a < std::uint32_t{request.address} + request.count; ++a) {
        const ExcdRegister* entry = a <= 0xFFFF ? table_.covering(static_cast<std::uint16_t>(a)) : nullptr;
        if (entry == nullptr) {
            return exception_of(fc::read_holding_registers, ExceptionCode::illegal_data_address);
        }
        response.values.push_back(word_of(*entry, static_cast<std::uint16_t>(a)));
    }
    return response;
}

std::int64_t ExcdModel::value_of(const ExcdRegister& entry) const {
    switch (entry.kind) {
        case ExcdKind::count_read:
        case ExcdKind::count_write: return counts_[entry.index];
        case ExcdKind::count_reset:
        case ExcdKind::io:
        case ExcdKind::save: return 0;
        case ExcdKind::setting:
        case ExcdKind::motion:
        case ExcdKind::variable: return stored_[table_.index_of(entry)];
        case ExcdKind::query: break;
    }
    const std::string_view n = entry.name;
    if (n == "rabs" || n == "renc") return position_;
    if (n == "rin") return inputs_;
    if (n == "rout") return outputs_;
    if (n == "rby") return motion_ ? 0 : 1;
    if (n == "rms") {
        const std::int64_t speed = motion_ ? motion_->speed() : 0;
        return speed > 0xFFFF ? 0xFFFF : speed;
    }
    if (n == "sensor") return (!motion_ && position_ == 0) ? 1 : 0;
    if (n == "ver") return version;
    if (n == "ralarm") return alarm_;
    return 0;  // rse, rsa: the manual gives only their names
}

std::uint16_t ExcdModel::word_of(const ExcdRegister& entry, std::uint16_t address) const {
    const std::int64_t value = value_of(entry);
    if (entry.words == 1) return static_cast<std::uint16_t>(value & 0xFFFF);
    const WordPair pair = split_u32(static_cast<std::uint32_t>(value & 0xFFFFFFFF), high_word_first_);
    return address == entry.address ? pair.first : pair.second;
}

std::int64_t ExcdModel::decode_value(const ExcdRegister& entry, const std::uint16_t* words) const {
    if (entry.words == 1) return words[0];
    const std::uint32_t raw = join_u32(words[0], words[1], high_word_first_);
    if (signed_range(entry)) return static_cast<std::int32_t>(raw);
    return raw;
}

std::optional<protocol::ExceptionCode> ExcdModel::write(std::uint16_t address,
                                                        const std::vector<std::uint16_t>& values,
                                                        Clock::time_point now) {
    // Check everything first: a rejected write changes nothing.
    struct Pending {
        const ExcdRegister* entry;
        std::int64_t value;
    };
    std::vector<Pending> pending;
    std::size_t i = 0;
    while (i < values.size()) {
        const std::uint32_t a = std::uint32_t{address} + static_cast<std::uint32_t>(i);
        const ExcdRegister* entry = a <= 0xFFFF ? table_.covering(static_cast<std::uint16_t>(a)) : nullptr;
        // Unknown address, half of a pair (starting on its second register or ending
        // after its first), or a read-only query: 02.
        if (entry == nullptr || entry->address != a || i + entry->words > values.size() ||
            entry->kind == ExcdKind::query || entry->kind == ExcdKind::count_read) {
            return ExceptionCode::illegal_data_address;
        }
        const std::int64_t value = decode_value(*entry, &values[i]);
        if (value < entry->min || value > entry->max) return ExceptionCode::illegal_data_value;
        // A drive in alarm refuses to move (it still stops).
        if (entry->kind == ExcdKind::motion && !is_stop(entry->name) && alarm_ != 0) {
            return ExceptionCode::server_device_failure;
        }
        pending.push_back({entry, value});
        i += entry->words;
    }
    for (const auto& p : pending) apply(*p.entry, p.value, now);
    return std::nullopt;
}

std::int64_t ExcdModel::setting(std::string_view name) const {
    for (const auto& entry : table_.entries()) {
        if (entry.name == name) return stored_[table_.index_of(entry)];
    }
    return 0;
}

std::int64_t ExcdModel::clamp_to_soft_limits(std::int64_t target) const {
    if (setting("solmsw") == 0) return target;
    const std::int64_t upper = setting("solm+");
    const std::int64_t lower = setting("solm-");
    if (target > upper) return upper;
    if (target < lower) return lower;
    return target;
}

void ExcdModel::start(MotionKind kind, std::int64_t target, std::int64_t speed, Clock::time_point now) {
    motion_kind_ = kind;
    motion_.emplace(now, position_, kind == MotionKind::home ? target : clamp_to_soft_limits(target), speed);
}

void ExcdModel::apply(const ExcdRegister& entry, std::int64_t value, Clock::time_point now) {
    const std::string_view n = entry.name;
    switch (entry.kind) {
        case ExcdKind::setting:
        case ExcdKind::variable: stored_[table_.index_of(entry)] = value; return;
        case ExcdKind::count_write: counts_[entry.index] = value; return;
        case ExcdKind::count_reset: counts_[entry.index] = 0; return;
        case ExcdKind::save: return;  // flash write: nothing to simulate
        case ExcdKind::io:
            if (n == "outon") outputs_ = static_cast<std::uint16_t>(outputs_ | value);
            if (n == "outoff") outputs_ = static_cast<std::uint16_t>(outputs_ & ~value);
            if (n == "clear") outputs_ = 0;
            return;
        case ExcdKind::query:
        case ExcdKind::count_read: return;  // write() refuses these with 02
        case ExcdKind::motion: break;
    }
    stored_[table_.index_of(entry)] = value;
    if (n == "abs") {
        start(MotionKind::move, value, setting("svr"), now);
    } else if (n == "rel") {
        start(MotionKind::move, position_ + value, setting("svr"), now);
    } else if (n == "start") {
        start(MotionKind::move, setting("sabs"), setting("svr"), now);
    } else if (n == "home") {
        start(MotionKind::home, 0, setting("hvr"), now);
    } else if (n == "jog") {
        // seed 002: 1 / 0xFFFFFFFF inch one pulse; 0x007EA5E0 / 0xFF815A20 run on to the
        // end of the position range; any other value inches that many pulses.
        std::int64_t target = position_ + value;
        if (value == excd_position_max || value == excd_position_min) target = value;
        start(MotionKind::jog, target, setting("jvr"), now);
    } else if (n == "stop" || n == "mstop" || (n == "jogstop" && motion_kind_ == MotionKind::jog)) {
        motion_.reset();
    }
}

void ExcdModel::advance(Clock::time_point now) {
    if (now < last_advance_) now = last_advance_;
    last_advance_ = now;
    if (!motion_) return;
    position_ = motion_->position_at(now);
    if (motion_->done_at(now)) motion_.reset();
}

std::string ExcdModel::control(std::string_view command, Clock::time_point now) {
    advance(now);
    const auto words = split_words(command);
    if (words.size() == 2 && words[0] == "alarm") {
        const auto code = parse_integer(words[1]);
        if (!code || *code < 1 || *code > 0xFFFF) {
            return "excd203mb: alarm code must be 1-65535 (ralarm 0x02D6), got \"" +
                   std::string(words[1]) + "\"";
        }
        alarm_ = static_cast<std::uint16_t>(*code);
        motion_.reset();  // a drive in alarm stops
        return {};
    }
    if (words.size() == 1 && words[0] == "clear") {
        alarm_ = 0;
        return {};
    }
    if (words.size() == 2 && words[0] == "inputs") {
        const auto mask = parse_integer(words[1]);
        if (!mask || *mask < 0 || *mask > 0xFFFF) {
            return "excd203mb: inputs must be a mask 0-0xFFFF (rin 0x0203), got \"" +
                   std::string(words[1]) + "\"";
        }
        inputs_ = static_cast<std::uint16_t>(*mask);
        return {};
    }
    return unknown_control("excd203mb", command, "alarm <code>, clear, inputs <mask>");
}

std::unique_ptr<BusDevice> make_excd(std::uint8_t address, ExcdOptions options) {
    return std::make_unique<ExcdModel>(address, options);
}

}  // namespace fieldbridge::sim
