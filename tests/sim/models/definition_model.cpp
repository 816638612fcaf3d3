#include "models/definition_model.hpp"

#include <charconv>
#include <stdexcept>
#include <string>

#include "models/modbus_request.hpp"
#include "models/point_text.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using core::RegisterTable;
using protocol::ExceptionCode;
namespace fc = protocol::fc;

constexpr std::uint8_t max_address = 247;  // Modbus over Serial Line 2.2

std::pair<std::string_view, std::string_view> first_word(std::string_view text) {
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    const auto space = text.find(' ');
    if (space == std::string_view::npos) return {text, {}};
    auto rest = text.substr(space + 1);
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    return {text.substr(0, space), rest};
}

std::optional<std::uint32_t> parse_number(std::string_view text) {
    int base = 10;
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        text.remove_prefix(2);
        base = 16;
    }
    std::uint32_t value = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size()) return std::nullopt;
    return value;
}

}  // namespace

bool DefinitionModel::Table::has(std::size_t address, std::size_t count) const noexcept {
    if (address + count > present.size()) return false;
    for (std::size_t a = address; a < address + count; ++a) {
        if (!present[a]) return false;
    }
    return true;
}

DefinitionModel::DefinitionModel(std::uint8_t address, std::shared_ptr<const DefinitionSpec> spec)
    : address_(address), spec_(std::move(spec)) {
    if (address < 1 || address > max_address) {
        throw std::invalid_argument(spec_->name + ": address " + std::to_string(address) +
                                    " is outside 1-247 (0 is the broadcast address)");
    }
    for (const auto& point : spec_->points.points) {
        for (std::size_t a = point.address; a < std::size_t{point.address} + point.width(); ++a) {
            table(point.table).present[a] = true;
        }
    }
    for (const auto& block : spec_->blocks) {
        for (std::size_t a = block.address; a < std::size_t{block.address} + block.count && a < 0x10000; ++a) {
            table(block.table).present[a] = true;
        }
    }
}

std::uint16_t DefinitionModel::value(RegisterTable t, std::uint16_t address) const noexcept {
    return tables_[static_cast<std::size_t>(t)].values[address];
}

std::optional<protocol::Bytes> DefinitionModel::on_frame(protocol::ByteView frame, Clock::time_point) {
    const auto request = accept_rtu(frame, address_, protocol::modbus_broadcast_address);
    if (!request) return std::nullopt;
    const std::uint8_t function = request->pdu[0];
    const bool known = function == fc::read_coils || function == fc::read_discrete_inputs ||
                       function == fc::read_holding_registers || function == fc::read_input_registers ||
                       function == fc::write_single_coil || function == fc::write_single_register ||
                       function == fc::write_multiple_coils || function == fc::write_multiple_registers ||
                       function == fc::mask_write_register;
    if (!known) return rtu_reply(*request, address_, exception_of(function, ExceptionCode::illegal_function));
    auto decoded = decode_or_exception(request->pdu);
    if (auto* error = std::get_if<protocol::Response>(&decoded)) return rtu_reply(*request, address_, *error);
    return rtu_reply(*request, address_, handle(std::get<protocol::Request>(decoded)));
}

protocol::Response DefinitionModel::handle(const protocol::Request& request) {
    const auto refused = [](std::uint8_t function) { return exception_of(function, ExceptionCode::illegal_data_address); };
    if (const auto* read = std::get_if<protocol::ReadBitsRequest>(&request)) {
        const auto& t = table(read->function == fc::read_coils ? RegisterTable::coils : RegisterTable::discrete_inputs);
        if (!t.has(read->address, read->count)) return refused(read->function);
        protocol::ReadBitsResponse response{read->function, {}};
        for (std::size_t a = read->address; a < std::size_t{read->address} + read->count; ++a) {
            response.bits.push_back(t.values[a] != 0);
        }
        return response;
    }
    if (const auto* read = std::get_if<protocol::ReadRegistersRequest>(&request)) {
        const auto& t = table(read->function == fc::read_holding_registers ? RegisterTable::holding : RegisterTable::input);
        if (!t.has(read->address, read->count)) return refused(read->function);
        protocol::ReadRegistersResponse response{read->function, {}};
        for (std::size_t a = read->address; a < std::size_t{read->address} + read->count; ++a) {
            response.values.push_back(t.values[a]);
        }
        return response;
    }
    auto& coils = table(RegisterTable::coils);
    auto& holding = table(RegisterTable::holding);
    if (const auto* single = std::get_if<protocol::WriteSingleCoilRequest>(&request)) {
        if (!coils.has(single->address, 1)) return refused(fc::write_single_coil);
        coils.values[single->address] = single->value ? 1 : 0;
        return protocol::WriteSingleResponse{fc::write_single_coil, single->address,
                                             static_cast<std::uint16_t>(single->value ? 0xFF00 : 0)};
    }
    if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        if (!holding.has(single->address, 1)) return refused(fc::write_single_register);
        holding.values[single->address] = single->value;
        return protocol::WriteSingleResponse{fc::write_single_register, single->address, single->value};
    }
    if (const auto* multiple = std::get_if<protocol::WriteMultipleCoilsRequest>(&request)) {
        if (!coils.has(multiple->address, multiple->values.size())) return refused(fc::write_multiple_coils);
        for (std::size_t i = 0; i < multiple->values.size(); ++i) {
            coils.values[multiple->address + i] = multiple->values[i] ? 1 : 0;
        }
        return protocol::WriteMultipleResponse{fc::write_multiple_coils, multiple->address,
                                               static_cast<std::uint16_t>(multiple->values.size())};
    }
    if (const auto* mask = std::get_if<protocol::MaskWriteRegisterRequest>(&request)) {
        if (!holding.has(mask->address, 1)) return refused(fc::mask_write_register);
        holding.values[mask->address] = mask->applied_to(holding.values[mask->address]);
        return protocol::MaskWriteResponse{mask->address, mask->and_mask, mask->or_mask};
    }
    const auto& multiple = std::get<protocol::WriteMultipleRegistersRequest>(request);
    if (!holding.has(multiple.address, multiple.values.size())) return refused(fc::write_multiple_registers);
    for (std::size_t i = 0; i < multiple.values.size(); ++i) holding.values[multiple.address + i] = multiple.values[i];
    return protocol::WriteMultipleResponse{fc::write_multiple_registers, multiple.address,
                                           static_cast<std::uint16_t>(multiple.values.size())};
}

std::string DefinitionModel::control(std::string_view command, Clock::time_point) {
    const auto [verb, args] = first_word(command);
    if (verb == "set") {
        const auto [name, value] = first_word(args);
        if (name.empty() || value.empty()) return "usage: set POINT VALUE, e.g. set temperature 21.5";
        return set_point(name, value);
    }
    if (verb == "set-register") return set_register(args);
    return spec_->name + ": unknown command '" + std::string(verb) +
           "'; use set POINT VALUE or set-register TABLE ADDRESS VALUE...";
}

std::string DefinitionModel::set_point(std::string_view name, std::string_view text) {
    for (const auto& point : spec_->points.points) {
        if (point.name != name) continue;
        auto& t = table(point.table);
        const auto encoded = registers_of_text(point, text, t.values[point.address]);
        if (!encoded.error.empty()) return "point " + point.name + ": " + encoded.error;
        for (std::size_t i = 0; i < encoded.registers.size(); ++i) t.values[point.address + i] = encoded.registers[i];
        return {};
    }
    std::string names;
    for (const auto& point : spec_->points.points) names += (names.empty() ? "" : ", ") + point.name;
    return spec_->name + " has no point '" + std::string(name) + "'; its points: " + names;
}

std::string DefinitionModel::set_register(std::string_view args) {
    const auto [table_name, rest] = first_word(args);
    const auto [address_text, values_text] = first_word(rest);
    const auto which = core::parse<RegisterTable>(table_name);
    const auto address = parse_number(address_text);
    if (!which || !address || *address > 0xFFFF || values_text.empty()) {
        return "usage: set-register TABLE ADDRESS VALUE..., TABLE one of coils, discrete_inputs, holding, input; "
               "e.g. set-register input 0x0004 0x0001";
    }
    std::vector<std::uint16_t> values;
    for (auto remaining = values_text; !remaining.empty();) {
        const auto [word, next] = first_word(remaining);
        const auto value = parse_number(word);
        const std::uint32_t limit = core::is_bit_table(*which) ? 1 : 0xFFFF;
        if (!value || *value > limit) return "'" + std::string(word) + "' is not a value 0.." + std::to_string(limit);
        values.push_back(static_cast<std::uint16_t>(*value));
        remaining = next;
    }
    auto& t = table(*which);
    if (!t.has(*address, values.size())) {
        return "the definition has no " + std::string(table_name) + " at " + std::string(address_text) + " (+" +
               std::to_string(values.size()) + ")";
    }
    for (std::size_t i = 0; i < values.size(); ++i) t.values[*address + i] = values[i];
    return {};
}

}  // namespace fieldbridge::sim
