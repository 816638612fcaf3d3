#pragma once
/// @file operations.hpp
/// A device type's MQTT operations (docs/mqtt.md, "Commands"), published by its
/// profile: each operation's name, its JSON fields with their types and ranges, and
/// how the validated fields become register writes. The MQTT side reads a command's
/// fields against these specs and asks the operation for its requests; it holds no
/// register address of any device. No JSON here: values arrive already typed.
///
/// Operation tables have static storage: an OperationSet stays valid after the
/// profile that published it is gone (a source detached on reload still answers).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "engine/register_image.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

/// Any JSON number within [min, max].
struct NumberField {
    double min = 0;
    double max = 0;
};
/// An integer (a number with no fraction) within [min, max].
struct IntegerField {
    std::int64_t min = 0;
    std::int64_t max = 0;
};
/// true or false.
struct BooleanField {};
/// One of the strings in @c options.
struct ChoiceField {
    std::vector<std::string_view> options;
};
using FieldType = std::variant<NumberField, IntegerField, BooleanField, ChoiceField>;

/// One JSON field of an operation.
struct OperationField {
    std::string_view name;
    FieldType type;
    bool optional = false;  ///< absent: the operation does without it
};

/// A validated field's value: NumberField -> double, IntegerField -> std::int64_t,
/// BooleanField -> bool, ChoiceField -> the option given.
using ArgumentValue = std::variant<double, std::int64_t, bool, std::string>;

/// The validated fields of one command, by name. Reading a field the operation does
/// not declare, or as another type, is a bug in the table: std::logic_error.
class OperationArgs {
public:
    void set(std::string_view name, ArgumentValue value);

    [[nodiscard]] bool has(std::string_view name) const noexcept;
    [[nodiscard]] double number(std::string_view name) const;
    [[nodiscard]] std::int64_t integer(std::string_view name) const;
    [[nodiscard]] bool boolean(std::string_view name) const;
    [[nodiscard]] const std::string& choice(std::string_view name) const;

private:
    template <typename T>
    [[nodiscard]] const T& get(std::string_view name) const;

    std::vector<std::pair<std::string_view, ArgumentValue>> values_;
};

/// One register value the gateway holds for a device.
struct RegisterValue {
    Table table = Table::holding;
    std::uint16_t address = 0;
    std::uint16_t value = 0;
    bool operator==(const RegisterValue&) const = default;
};

/// The operation depends on a register the gateway has no usable value of: nothing
/// may be sent. @c message names the register and what to do instead.
struct StateUnknown {
    std::string message;
};

/// The requests, in order (each after the previous one was acknowledged), or why
/// the device's state does not allow to choose them.
using OperationWrites = std::variant<std::vector<protocol::Request>, StateUnknown>;

/// Every register value the gateway holds for a device.
using RegisterValues = std::span<const RegisterValue>;

/// The requests for validated @p args; @p registers: what the gateway holds of the
/// device's registers (most operations ignore them).
using WritesFunction = OperationWrites (*)(const OperationArgs& args, RegisterValues registers);

struct Operation {
    std::string_view name;
    std::vector<OperationField> fields;  ///< read in this order: the first refusal is reported
    WritesFunction writes = nullptr;
};

/// The operations of a device type. The default (a generic Modbus device) has none
/// of its own: only the raw register ops every device takes (docs/mqtt.md).
struct OperationSet {
    std::string_view name = "generic";  ///< in messages: "op 'x' is not a <name> command"
    std::span<const Operation> operations;

    /// nullptr when the set has no operation @p op.
    [[nodiscard]] const Operation* find(std::string_view op) const noexcept;
};

/// A state field that one operation sets by itself: writing the field (a Sparkplug
/// DCMD, docs/sparkplug.md "Commands") is the operation @c op with the value as its
/// field @c argument. E.g. the WTEC `force_pct` is op `force` with `percent`.
struct FieldSetter {
    std::string_view field;
    std::string_view op;
    std::string_view argument;
};

/// The fields of @p operations' device type that an operation sets (static storage);
/// empty for a type with none.
[[nodiscard]] std::span<const FieldSetter> field_setters(const OperationSet& operations) noexcept;

// ---- helpers for the tables -----------------------------------------------------

/// One FC06.
[[nodiscard]] OperationWrites write_single(std::uint16_t address, std::uint16_t value);
/// One FC16 of @p values from @p address.
[[nodiscard]] OperationWrites write_multiple(std::uint16_t address, std::vector<std::uint16_t> values);

/// A signed 32-bit value as two registers, high word first (the northbound view,
/// docs/registers.md; a low-first device's profile turns them round on the wire).
[[nodiscard]] std::vector<std::uint16_t> high_word_first(std::int64_t value);

/// A value in units of 0.01 (mm, mm/s), rounded, as a register value.
[[nodiscard]] std::uint16_t hundredths(double value);

/// The value of @p address in @p table, if the gateway holds one.
[[nodiscard]] std::optional<std::uint16_t> register_value(RegisterValues registers, Table table,
                                                          std::uint16_t address) noexcept;

}  // namespace fieldbridge::engine
