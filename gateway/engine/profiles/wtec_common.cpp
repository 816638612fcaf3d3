#include "engine/profiles/wtec_common.hpp"

#include <string>
#include <utility>
#include <variant>

#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

// ---- MQTT operations (docs/mqtt.md, "wtec-rtu and wtec-ascii") ------------------

/// The position (0x0105) that closes (@p close) or opens the jaws. Position 0 % is the
/// end the gripper homes to (seed 003 table 2.9: direction 1 runs to the maximum
/// opening "as the initial start point", 2 to the minimum closing), so closing is
/// 100 % with direction 1 and 0 % with direction 2.
[[nodiscard]] std::variant<std::uint16_t, StateUnknown> wtec_jaw_position(RegisterValues registers, bool close,
                                                                          std::string_view op) {
    using namespace wtec_reg;
    const auto direction = register_value(registers, Table::holding, init_direction);
    const std::string what = "op '" + std::string(op) + "' needs the gripper's init direction (holding " +
                             hex_word(init_direction) + "), ";
    const std::string instead = "; retry in a few seconds (it is polled every `poll.slow`) or use the 'position' op "
                                "with an explicit percent; nothing was sent";
    if (!direction) {
        return StateUnknown{what + "which was not read from the device yet" + instead};
    }
    if (*direction != direction_open && *direction != direction_close) {
        return StateUnknown{what + "which reads " + std::to_string(*direction) + " (neither 1 open nor 2 close)" +
                            instead};
    }
    const bool zero_is_open = *direction == direction_open;
    return std::uint16_t{close == zero_is_open ? std::uint16_t{100} : std::uint16_t{0}};
}

/// grip / release: the optional force and speed first, then the position that moves
/// the jaws.
[[nodiscard]] OperationWrites wtec_approach(const OperationArgs& a, RegisterValues registers, bool close,
                                            std::string_view op) {
    using namespace wtec_reg;
    const auto target = wtec_jaw_position(registers, close, op);
    if (const auto* unknown = std::get_if<StateUnknown>(&target)) return *unknown;
    std::vector<protocol::Request> out;
    if (a.has("force_pct")) {
        out.emplace_back(protocol::WriteSingleRegisterRequest{force, static_cast<std::uint16_t>(a.integer("force_pct"))});
    }
    if (a.has("speed_pct")) {
        out.emplace_back(protocol::WriteSingleRegisterRequest{speed, static_cast<std::uint16_t>(a.integer("speed_pct"))});
    }
    out.emplace_back(protocol::WriteSingleRegisterRequest{position, std::get<std::uint16_t>(target)});
    return out;
}

// Tables 2.5 (force 20-100 %), 2.7 (speed 1-100 %), 2.6 (position 0-100 %).
constexpr IntegerField wtec_force_range{20, 100};
constexpr IntegerField wtec_speed_range{1, 100};

/// One register set to the op's `percent`.
template <std::uint16_t Address>
[[nodiscard]] OperationWrites wtec_percent(const OperationArgs& a, RegisterValues) {
    return write_single(Address, static_cast<std::uint16_t>(a.integer("percent")));
}

[[nodiscard]] const std::vector<Operation>& wtec_operation_table() {
    using namespace wtec_reg;
    static const std::vector<Operation> table{
        {"init", {}, [](const OperationArgs&, RegisterValues) { return write_single(initialize, 1); }},
        {"grip",
         {{"force_pct", wtec_force_range, true}, {"speed_pct", wtec_speed_range, true}},
         [](const OperationArgs& a, RegisterValues r) { return wtec_approach(a, r, true, "grip"); }},
        {"release",
         {{"force_pct", wtec_force_range, true}, {"speed_pct", wtec_speed_range, true}},
         [](const OperationArgs& a, RegisterValues r) { return wtec_approach(a, r, false, "release"); }},
        {"position", {{"percent", IntegerField{0, 100}}}, wtec_percent<position>},
        {"force", {{"percent", wtec_force_range}}, wtec_percent<force>},
        {"speed", {{"percent", wtec_speed_range}}, wtec_percent<speed>},
        {"estop", {}, [](const OperationArgs&, RegisterValues) { return write_single(estop, 1); }},
    };
    return table;
}

}  // namespace

OperationSet wtec_operations() { return OperationSet{"wtec", wtec_operation_table()}; }

std::span<const FieldSetter> wtec_field_setters() noexcept {
    static constexpr FieldSetter setters[] = {
        {"target_pct", "position", "percent"},
        {"force_pct", "force", "percent"},
        {"speed_pct", "speed", "percent"},
    };
    return setters;
}

bool wtec_in_motion(const RegisterImage& image) {
    return image.value(Table::holding, wtec_reg::grip_state) == wtec_reg::grip_moving ||
           image.value(Table::holding, wtec_reg::init_state) == wtec_reg::init_running;
}

}  // namespace fieldbridge::engine
