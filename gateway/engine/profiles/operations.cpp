#include "engine/profiles/operations.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fieldbridge::engine {

void OperationArgs::set(std::string_view name, ArgumentValue value) {
    values_.emplace_back(name, std::move(value));
}

bool OperationArgs::has(std::string_view name) const noexcept {
    return std::any_of(values_.begin(), values_.end(), [name](const auto& v) { return v.first == name; });
}

template <typename T>
const T& OperationArgs::get(std::string_view name) const {
    const auto it = std::find_if(values_.begin(), values_.end(), [name](const auto& v) { return v.first == name; });
    if (it == values_.end()) {
        throw std::logic_error("operation field '" + std::string(name) + "' was not given");
    }
    const T* value = std::get_if<T>(&it->second);
    if (value == nullptr) {
        throw std::logic_error("operation field '" + std::string(name) + "' is read as another type");
    }
    return *value;
}

double OperationArgs::number(std::string_view name) const { return get<double>(name); }
std::int64_t OperationArgs::integer(std::string_view name) const { return get<std::int64_t>(name); }
bool OperationArgs::boolean(std::string_view name) const { return get<bool>(name); }
const std::string& OperationArgs::choice(std::string_view name) const { return get<std::string>(name); }

const Operation* OperationSet::find(std::string_view op) const noexcept {
    const auto it = std::find_if(operations.begin(), operations.end(), [op](const Operation& o) { return o.name == op; });
    return it == operations.end() ? nullptr : &*it;
}

OperationWrites write_single(std::uint16_t address, std::uint16_t value) {
    return std::vector<protocol::Request>{protocol::WriteSingleRegisterRequest{address, value}};
}

OperationWrites write_multiple(std::uint16_t address, std::vector<std::uint16_t> values) {
    return std::vector<protocol::Request>{protocol::WriteMultipleRegistersRequest{address, std::move(values)}};
}

std::vector<std::uint16_t> high_word_first(std::int64_t value) {
    const auto bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(value));
    return {static_cast<std::uint16_t>(bits >> 16), static_cast<std::uint16_t>(bits & 0xFFFFU)};
}

std::uint16_t hundredths(double value) { return static_cast<std::uint16_t>(std::lround(value * 100.0)); }

std::optional<std::uint16_t> register_value(RegisterValues registers, Table table, std::uint16_t address) noexcept {
    const auto it = std::find_if(registers.begin(), registers.end(), [&](const RegisterValue& r) {
        return r.table == table && r.address == address;
    });
    if (it == registers.end()) return std::nullopt;
    return it->value;
}

}  // namespace fieldbridge::engine
