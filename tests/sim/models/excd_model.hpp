#pragma once
/// @file excd_model.hpp
/// EXCD203MB(-E) stepper controller in Modbus-RTU mode (seed 002): holding registers
/// only, FC03 / FC06 / FC10 (anything else: exception 01). Addresses 1-254, broadcast
/// 0xFF (acts, never answers).
///
/// Rules (README.md beside this file has the full list):
/// - An address outside the table of seed 002 section 4 -> 02, for reads and writes.
/// - 32-bit values are register pairs in the configured word order (default high word
///   first, as the CRC-verified solm+ example shows). A write must cover whole pairs:
///   a write that covers one register of a pair -> 02 (also FC06 on a pair). Reads may
///   cover half a pair and return that half, since a read changes nothing.
/// - Writing a query register (rms, rabs, ... ralarm, rcount) -> 02; a value outside the
///   manual's range -> 03; a motion command while an alarm is set -> 04.
/// - Motion at constant speed, no ramps: abs / rel / sabs+start at svr pulses/s, jog at
///   jvr (1 / -1: one pulse; +-8,300,000: continuous until jogstop or a soft limit;
///   other values: that many pulses), home to 0 at hvr. Soft limits clamp targets when
///   solmsw is not 0. stop / mstop end any motion at once, jogstop ends a jog.
/// - rby (0x0205) = 0 busy, 1 idle; rms = running speed (pulses/s, saturated at
///   0xFFFF); rin = inputs (0x000F at power-up, the manual's example); rout = outputs
///   (outon sets the bits of its value, outoff clears them, clear clears all);
///   sensor bit 0 = home sensor (at position 0); ver = 120 (protocol V1.2); rse and rsa
///   have no meaning in the manual and read 0; renc = rabs (no following error);
///   ralarm = injected alarm code.
/// - save (0x0303 = 0) is acknowledged (the manual shows the frame without a reply).
///
/// Control commands: "alarm <code 1-65535>", "clear", "inputs <mask 0-0xFFFF>".

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "models/bus_device.hpp"
#include "models/excd_registers.hpp"
#include "models/linear_move.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

struct ExcdOptions {
    bool high_word_first = true;
};

class ExcdModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 1-254.
    ExcdModel(std::uint8_t address, ExcdOptions options);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::modbus_rtu; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "excd203mb"; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point now) override;
    void advance(Clock::time_point now) override;
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

    [[nodiscard]] std::int64_t position() const noexcept { return position_; }
    [[nodiscard]] bool busy() const noexcept { return motion_.has_value(); }

private:
    enum class MotionKind : std::uint8_t { move, home, jog };

    [[nodiscard]] protocol::Response handle(const protocol::Request& request, Clock::time_point now);
    [[nodiscard]] protocol::Response read(const protocol::ReadRegistersRequest& request) const;
    /// Writes whole entries; @p values start at @p address. Returns the exception, if any.
    [[nodiscard]] std::optional<protocol::ExceptionCode> write(std::uint16_t address,
                                                               const std::vector<std::uint16_t>& values,
                                                               Clock::time_point now);
    [[nodiscard]] std::int64_t value_of(const ExcdRegister& entry) const;
    [[nodiscard]] std::uint16_t word_of(const ExcdRegister& entry, std::uint16_t address) const;
    [[nodiscard]] std::int64_t decode_value(const ExcdRegister& entry, const std::uint16_t* words) const;
    void apply(const ExcdRegister& entry, std::int64_t value, Clock::time_point now);
    [[nodiscard]] std::int64_t setting(std::string_view name) const;
    void start(MotionKind kind, std::int64_t target, std::int64_t speed, Clock::time_point now);
    [[nodiscard]] std::int64_t clamp_to_soft_limits(std::int64_t target) const;

    std::uint8_t address_;
    bool high_word_first_;
    ExcdRegisterTable table_;
    std::vector<std::int64_t> stored_;  ///< per table entry: settings, last motion values, variables
    std::vector<std::int64_t> counts_;  ///< counters 1-50 (rcount / cnt / rstcount)

    std::int64_t position_ = 0;  ///< pulses
    std::optional<LinearMove> motion_;
    MotionKind motion_kind_ = MotionKind::move;
    Clock::time_point last_advance_{};

    std::uint16_t inputs_ = 0x000F;  ///< seed 002 example 4: rin reads 0x000F
    std::uint16_t outputs_ = 0;
    std::uint16_t alarm_ = 0;
};

[[nodiscard]] std::unique_ptr<BusDevice> make_excd(std::uint8_t address, ExcdOptions options);

}  // namespace fieldbridge::sim
