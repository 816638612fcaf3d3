#include "northbound/upstream/r6_operations.hpp"

#include <cmath>
#include <vector>

#include "northbound/upstream/r6_map.hpp"

namespace fieldbridge::northbound::r6 {

namespace {

using engine::OperationArgs;
using engine::RegisterValues;

/// seed 004 3.2.1: an FC06 of any value executes the command; the gateway sends 1.
template <std::uint16_t Address>
[[nodiscard]] engine::OperationWrites r6_command(const OperationArgs&, RegisterValues) {
    return engine::write_single(Address, 1);
}

[[nodiscard]] const std::vector<engine::Operation>& r6_operation_table() {
    using engine::BooleanField;
    using engine::ChoiceField;
    using engine::IntegerField;
    using engine::NumberField;
    static const std::vector<engine::Operation> table{
        {"stop", {}, r6_command<command_stop>},
        {"pause", {}, r6_command<command_pause>},
        {"start", {}, r6_command<command_start_button>},
        // Both clear the alarm and move the robot again, so the caller says which.
        {"clear_alarm", {{"resume", ChoiceField{{"next", "continue"}}}},
         [](const OperationArgs& a, RegisterValues r) {
             return a.choice("resume") == "next" ? r6_command<command_clear_alarm_next>(a, r)
                                                 : r6_command<command_clear_alarm_continue>(a, r);
         }},
        {"global_speed", {{"percent", NumberField{0.0, 100.0}}},
         [](const OperationArgs& a, RegisterValues) {
             return engine::write_single(global_speed,
                                         static_cast<std::uint16_t>(std::lround(a.number("percent") * 10.0)));
         }},
        {"output", {{"board", IntegerField{0, 7}}, {"point", IntegerField{0, 31}}, {"on", BooleanField{}}},
         [](const OperationArgs& a, RegisterValues) {
             return engine::write_multiple(output_control, {static_cast<std::uint16_t>(a.integer("board")),
                                                            static_cast<std::uint16_t>(a.integer("point")),
                                                            static_cast<std::uint16_t>(a.boolean("on") ? 1 : 0)});
         }},
    };
    return table;
}

}  // namespace

engine::OperationSet r6_operations() { return engine::OperationSet{"r6", r6_operation_table()}; }

}  // namespace fieldbridge::northbound::r6
