#pragma once
/// @file device_profile.hpp
/// What the gateway knows about one device type (spec §2, §5): its register map and
/// function codes, value ranges, which writes are motion / stop / protected
/// commands, how a northbound Modbus request goes on the line, what to poll, how a
/// reply lands in the register image, and how to decode state and alarms.
///
/// Profiles are immutable after construction and hold no per-device state: the
/// register image is the state (the WTEC ASCII view keeps its e-stop latch there).
/// All methods are const and safe to call from the device's loop thread.
///
/// The northbound view is always high word first for 32-bit pairs, whatever the
/// device's word order on the wire (docs/registers.md).

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/device_type.hpp"
#include "core/error.hpp"
#include "core/modbus_ids.hpp"
#include "core/point.hpp"
#include "core/register_def.hpp"
#include "core/word_order.hpp"
#include "engine/profiles/operations.hpp"
#include "engine/profiles/poll_plan.hpp"
#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

using core::DeviceType;
using core::to_string;
using core::WordOrder;

enum class Bus : std::uint8_t { modbus_rtu, wtec_ascii };

struct PollPeriods {
    Duration fast = milliseconds{50};
    Duration slow = milliseconds{1000};
    Duration motion = milliseconds{20};
};

/// A register block of a generic Modbus device.
struct GenericBlock {
    Table table = Table::holding;
    std::uint16_t address = 0;
    std::uint16_t count = 0;  ///< 1-125 registers or 1-2000 bits
    Duration period = milliseconds{1000};
    bool writable = false;    ///< coils and holding only
};

/// A read of holding registers (FC03) that tells a device type apart from the others
/// on a bus scan (`fieldbridge scan`): the profile names it, the scan only sends it.
struct IdentificationRead {
    std::uint16_t address = 0;
    std::uint16_t count = 1;
};

/// Everything a profile takes from the configuration (mapped by the glue layer).
struct ProfileOptions {
    core::BusAddress address{1};  ///< the WTEC ASCII view shows it at 0x0303
    PollPeriods poll;
    bool allow_protected = false;                  ///< device ID / flash save / baud / mode writes
    WordOrder word_order = WordOrder::high_first;  ///< excd203mb
    std::optional<std::uint32_t> wtec_stroke;      ///< wtec-ascii: encoder counts for 100 %; required
    std::vector<GenericBlock> blocks;              ///< modbus: raw blocks (with points: optional)
    core::PointModel points;                       ///< modbus: named, typed points and their alarms
    /// Built-in types: the register map of a definition file that replaced the
    /// compiled-in one; empty: the compiled-in definition's (builtin_map.hpp).
    std::vector<core::RegisterDef> registers;
    /// Built-in types: the points and alarms of a definition file that decode the
    /// state; nullopt: the compiled-in definition's (builtin_map.hpp).
    std::optional<core::PointModel> builtin_state = std::nullopt;
};

/// Options a profile cannot work with; what() names the option and the fix.
class ProfileError : public core::Error {
public:
    using core::Error::Error;
};

/// What a northbound request is (spec §3 rules 2, 4, 5, 6; §4 protected registers).
struct Classification {
    bool write = false;            ///< a command (rule 2); reads are not
    bool motion = false;           ///< moves or stops the device: poll fast after it (rule 5)
    bool urgent_stop = false;      ///< stop / e-stop: ahead of other commands (rule 4)
    bool protected_write = false;  ///< device ID, flash save, baud / mode change
    bool idempotent = true;        ///< may be retried (rule 6): reads only
    bool operator==(const Classification&) const = default;
};

enum class ApplyStatus : std::uint8_t {
    applied,           ///< the reply is in the image
    device_exception,  ///< the device answered with a Modbus exception: `exception`
    not_applicable,    ///< the reply does not answer the payload: nothing changed
};

/// Something the device told us that is worth a log line and an MQTT event.
struct DeviceNotice {
    std::uint8_t code = 0;
    std::string text;
    bool operator==(const DeviceNotice&) const = default;
};

struct ApplyResult {
    ApplyStatus status = ApplyStatus::applied;
    std::optional<protocol::ExceptionCode> exception;
    /// A request to send next, for information only (not a command): XEG exception
    /// 0x04 asks for an FC07 read (seed 001 §4.2.4; spec §4).
    std::optional<Payload> follow_up;
    std::optional<DeviceNotice> notice;
};

/// A decoded value for MQTT: name, value, unit ("" when none). A list of numbers is
/// one value (R6 `axes_deg`, spec §6), published as a JSON array.
using FieldValue = std::variant<bool, std::int64_t, double, std::string, std::vector<double>>;
struct Field {
    std::string name;
    FieldValue value;
    std::string unit;
    bool operator==(const Field&) const = default;
};
struct DecodedState {
    std::vector<Field> fields;  ///< only fields whose registers are known
    [[nodiscard]] const Field* find(std::string_view name) const noexcept;
};

enum class Severity : std::uint8_t { warning, error, critical };
[[nodiscard]] std::string_view to_string(Severity severity) noexcept;

struct Alarm {
    std::string code;    ///< stable identifier, e.g. "emergency_stop"
    std::string text;    ///< for operators
    Severity severity = Severity::error;
    std::string source;  ///< the register it comes from, e.g. "input 0x0301"
    bool operator==(const Alarm&) const = default;
};

class DeviceProfile {
public:
    DeviceProfile() = default;
    virtual ~DeviceProfile() = default;
    DeviceProfile(const DeviceProfile&) = delete;
    DeviceProfile& operator=(const DeviceProfile&) = delete;

    [[nodiscard]] virtual DeviceType type() const noexcept = 0;
    [[nodiscard]] virtual Bus bus() const noexcept = 0;
    /// 0, or 0xFF for EXCD203MB (seed 002 §5).
    [[nodiscard]] virtual core::BusAddress broadcast_address() const noexcept = 0;

    /// Spec §4: the exception to answer locally, without touching the line: 0x01
    /// unsupported function code or protected register not enabled, 0x02 address
    /// outside the map / across a hole / half a 32-bit pair written, 0x03 quantity
    /// or value out of range, 0x0B a translation that needs device data not read yet
    /// (WTEC ASCII view). nullopt: send it.
    [[nodiscard]] virtual std::optional<protocol::ExceptionCode> validate(const protocol::Request& request,
                                                                          const RegisterImage& image) const = 0;

    /// Call on a request that validate() accepted.
    [[nodiscard]] virtual Classification classify(const protocol::Request& request) const = 0;

    /// What goes on the wire for a validated northbound request, in order. The agent
    /// sends them one after another, stops at the first that fails, and applies
    /// each reply. Empty: nothing to send (served from the image).
    [[nodiscard]] virtual std::vector<Payload> to_line(const protocol::Request& request,
                                                       const RegisterImage& image) const = 0;

    /// What to poll (a fresh plan; the agent keeps it and calls on_block_rejected).
    [[nodiscard]] virtual PollPlan poll_plan() const = 0;

    /// Puts the reply to @p sent into the image: reads fill registers, acknowledged
    /// writes update the written registers (as a read would now return them).
    [[nodiscard]] virtual ApplyResult apply(const Payload& sent, const Reply& reply, RegisterImage& image,
                                            TimePoint now) const = 0;

    /// The northbound answer to @p request, once @p replies (to to_line()'s payloads,
    /// in order, possibly fewer when one failed) have been applied: a device
    /// exception is passed through under the client's function code; a read is
    /// answered from the replies or the image; a write with its echo. 0x0B when the
    /// replies do not answer the request.
    [[nodiscard]] virtual protocol::Response respond(const protocol::Request& request,
                                                     std::span<const Reply> replies,
                                                     const RegisterImage& image) const = 0;

    /// Rule 5: the device is moving (poll the motion items at the motion period).
    [[nodiscard]] virtual bool in_motion(const RegisterImage& image) const = 0;
    [[nodiscard]] virtual DecodedState decode_state(const RegisterImage& image) const = 0;
    [[nodiscard]] virtual std::vector<Alarm> alarms(const RegisterImage& image) const = 0;

    /// The device type's MQTT operations (operations.hpp): what each takes and which
    /// registers it writes. Static storage: valid after this profile is gone.
    [[nodiscard]] virtual OperationSet operations() const = 0;
};

}  // namespace fieldbridge::engine
