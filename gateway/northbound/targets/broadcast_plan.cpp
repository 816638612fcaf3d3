#include "northbound/targets/broadcast_plan.hpp"

#include <algorithm>
#include <iterator>

namespace fieldbridge::northbound {
namespace {

using protocol::ExceptionCode;

/// The devices on one bus address.
struct Group {
    core::BusAddress address;
    std::optional<std::vector<engine::Payload>> payloads;  ///< of the first device that accepts
    std::optional<ExceptionCode> refusal;                  ///< of the first device that refuses
    bool disagree = false;                                 ///< accepting devices need different payloads
    engine::Duration delay_before{};
    bool urgent = true;
};

[[nodiscard]] bool modbus_only(const std::vector<engine::Payload>& payloads) {
    return !payloads.empty() && std::all_of(payloads.begin(), payloads.end(), [](const engine::Payload& p) {
        return std::holds_alternative<engine::ModbusPayload>(p);
    });
}

[[nodiscard]] bool same(const std::vector<engine::Payload>& a, const std::vector<engine::Payload>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const engine::Payload& x, const engine::Payload& y) {
        return std::get<engine::ModbusPayload>(x).request == std::get<engine::ModbusPayload>(y).request;
    });
}

}  // namespace

BroadcastPlan plan_broadcast(const protocol::Request& request, std::span<const BroadcastMember> members) {
    std::vector<Group> groups;
    std::optional<ExceptionCode> first_refusal;
    std::optional<ExceptionCode> first_telling_refusal;  // not 0x02
    const auto refuse = [&](Group& group, ExceptionCode code) {
        if (!group.refusal) group.refusal = code;
        if (!first_refusal) first_refusal = code;
        if (!first_telling_refusal && code != ExceptionCode::illegal_data_address) first_telling_refusal = code;
    };
    for (const BroadcastMember& member : members) {
        const engine::DeviceProfile& profile = *member.profile;
        if (profile.bus() != engine::Bus::modbus_rtu) continue;  // hears no Modbus broadcast
        const core::BusAddress address = profile.broadcast_address();
        auto found = std::find_if(groups.begin(), groups.end(), [&](const Group& g) { return g.address == address; });
        if (found == groups.end()) {
            groups.emplace_back().address = address;
            found = std::prev(groups.end());
        }
        Group& group = *found;
        if (const auto bad = profile.validate(request, *member.image)) {
            refuse(group, *bad);
            continue;
        }
        std::vector<engine::Payload> payloads = profile.to_line(request, *member.image);
        if (!modbus_only(payloads)) {
            // Answered from the image or not a Modbus request on the wire: not something
            // a broadcast can carry for this device.
            refuse(group, ExceptionCode::illegal_function);
            continue;
        }
        if (group.payloads && !same(*group.payloads, payloads)) group.disagree = true;
        if (!group.payloads) group.payloads = std::move(payloads);
        group.delay_before = std::max(group.delay_before, member.delay_before_command);
        group.urgent = group.urgent && profile.classify(request).urgent_stop;
    }
    BroadcastPlan plan;
    std::sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) { return a.address < b.address; });
    for (const Group& group : groups) {
        if (!group.payloads) continue;
        if (group.refusal || group.disagree) {
            plan.steps.clear();
            plan.refusal = group.refusal.value_or(ExceptionCode::illegal_function);
            return plan;
        }
        for (const engine::Payload& payload : *group.payloads) {
            plan.steps.push_back(BroadcastStep{group.address, payload, group.delay_before, group.urgent});
        }
    }
    if (plan.steps.empty()) {
        // No Modbus device on the line, or every device refuses.
        plan.refusal = first_telling_refusal.value_or(first_refusal.value_or(ExceptionCode::illegal_function));
    }
    return plan;
}

}  // namespace fieldbridge::northbound
