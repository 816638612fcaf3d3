#pragma once
/// @file broadcast_plan.hpp
/// What a write to a line's broadcast unit puts on the line, decided by the profiles
/// of the devices it reaches (docs/modbus-tcp.md, "Broadcast units"). Pure.
///
/// A broadcast reaches every device listening on its bus address (0 for Modbus
/// devices, 0xFF for the EXCD203MB; WTEC ASCII devices hear neither), and nobody
/// answers it, so the gateway must know before it sends that every device it reaches
/// takes it. Each Modbus device of the line validates the write as if it were
/// addressed to it (DeviceProfile::validate: protected registers, ranges, 32-bit
/// pairs) and says what it would put on the wire (to_line: translations such as the
/// XEG's FC06 -> FC16, word order). Then, per bus address:
///  - every device on it accepts, with the same payloads: those payloads go to it;
///  - every device on it refuses: nothing goes to it (the register is not theirs);
///  - its devices disagree (some accept, some refuse, or they would need different
///    payloads): the whole broadcast is refused, nothing is sent.
/// When no address is left the broadcast is refused with the first refusal in
/// configuration order that is not 0x02 (a device that knows the register and
/// refuses it says more than one that does not have it), else 0x02.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/modbus_ids.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

/// A device of the line, as the plan sees it.
struct BroadcastMember {
    const engine::DeviceProfile* profile = nullptr;
    const engine::RegisterImage* image = nullptr;
    engine::Duration delay_before_command{};  ///< rule 11
};

/// One transaction of the broadcast.
struct BroadcastStep {
    core::BusAddress address;  ///< 0 or 0xFF
    engine::Payload payload;
    engine::Duration delay_before{};  ///< the longest of the devices it reaches
    bool urgent = false;              ///< a stop for every device it reaches (rule 4)
};

struct BroadcastPlan {
    std::vector<BroadcastStep> steps;                  ///< by address, then in to_line() order
    std::optional<protocol::ExceptionCode> refusal;    ///< set: answer it, send nothing
};

/// @p request must be a write (FC05, 06, 0F, 10); @p members in configuration order.
[[nodiscard]] BroadcastPlan plan_broadcast(const protocol::Request& request,
                                           std::span<const BroadcastMember> members);

}  // namespace fieldbridge::northbound
