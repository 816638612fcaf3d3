#pragma once
/// @file r6_model.hpp
/// Huacheng R6 robot controller as a Modbus TCP slave (seed 004): the request PDU in,
/// the response PDU out (the TCP server strips and adds the MBAP header). Not a
/// BusDevice: the R6 sits on Ethernet, not on a serial bus.
///
/// Map (seed 004 sections 3-5; FC03 and FC04 read the same registers):
/// - 0x0000 version length (0x29: the 40 characters of "AM8-QC-RXE-7.8.02-bate7_FAKE_TGF_ENCODER"
///   and a NUL), 0x0001-0x0040 the string (two characters a register, high byte first,
///   padded with 0);
/// - 0x0082 counter count, 0x0083-0x0882 counter IDs (2 registers each, high word
///   first as the example shows; IDs past the last counter read 0xFFFF);
/// - 0x0883-0x0884 counter to read (FC10, an existing ID), 0x0885-0x0886 its target,
///   0x0887-0x0888 its current value;
/// - 0x0889 mode (3 at power-up, the manual's example; 2 auto after a start),
///   0x088A IO board count (1);
/// - 0x088B-0x089C inputs, 0x08B3-0x08C4 outputs (FC10): 32 bits a board, high word
///   first; IO boards 0-4 (only those below the board count), M boards 0-2, EU board;
/// - 0x08DB axis count (6), 0x08DC-0x08EB axis positions (only existing axes),
///   0x091C-0x092B world coordinates: signed 32-bit x1000, high word first;
/// - 0x095C alarm number, 0x095D / 0x0961 current / last cycle time (ms, 64-bit in 4
///   registers), 0x0965 host address (1), 0x0966-0x096D torque (2580 = rated),
///   0x0986-0x098D speed (rpm), 0x09A6 move state, 0x09A7 origin state;
/// - FC06 0x4E20-0x4E26 commands (any value): stop, pause, single cycle, start button,
///   stop button, clear alarm and run the next step, clear alarm and continue;
/// - 0x4EE8 global speed 0-1000 (FC06, FC03);
/// - FC10 0x4E52 counter modify (6 registers: ID, target ignored, current), 0x4E58
///   single output (3 registers: board 0-8, point 0-31, state 0-1);
/// - 0x4F4C-0x56D5 parameter table (965 signed 32-bit values, FC10 and FC03);
/// - 0x7530 data source to view, 0x7531 its point count, 0x7532-0x7534 data source to
///   modify / values per point (4 or 6) / axis mask, 0x7535... upload: point count,
///   clear flag (0x7536), then the points (2 registers a value);
/// - FC01 / FC05 coils 0x0000-0x011F: Y outputs of IO boards 0-4, M, EUY (board =
///   coil / 32, bit = coil % 32), 0xFF00 on, 0x0000 off.
///
/// Every multi-register value must be read and written whole, from its first register
/// (seed 004: "the start address must be the start of an axis / board / ID", "the count
/// must be even"): anything else, an unknown address, or an axis / board that does not
/// exist is exception 02. A value outside its range is 03; other function codes 01.
///
/// Motion: after a start (command 0x4E23 or control "start", refused while an alarm is
/// set or the origins are not set) the move state is 1 and the axes sweep back and forth
/// (axis i between 0 and 30+10*i degrees at 10 deg/s times the global speed); one sweep
/// of axis 0 is one cycle: it updates the cycle times and counts up counter 0. World
/// coordinates equal the axis values (a Cartesian robot). An alarm stops the robot.
///
/// Control commands: "start", "stop", "alarm <n>", "clear", "mode <n>",
/// "io_boards <0-5>", "axes <0-8>", "origin <0|1>", "input <board 0-8> <32-bit value>".

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "models/bus_device.hpp"
#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

class R6Model {
public:
    R6Model();

    /// The response PDU (normal or exception) to @p request_pdu at simulated time @p now.
    [[nodiscard]] protocol::Bytes handle_pdu(protocol::ByteView request_pdu, Clock::time_point now);
    /// Test/demo control; returns an error text or empty on success.
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now);
    /// Moves the robot on to @p now (handle_pdu and control call it too).
    void advance(Clock::time_point now);

    [[nodiscard]] bool moving() const noexcept { return moving_; }
    [[nodiscard]] std::uint16_t alarm() const noexcept { return alarm_; }
    [[nodiscard]] std::int32_t axis_position(std::size_t axis) const noexcept;

    static constexpr std::size_t max_axes = 8;
    static constexpr std::size_t board_count = 9;  ///< IO 0-4, M 0-2, EU 0
    static constexpr std::size_t parameter_count = 965;

private:
    struct Counter {
        std::uint32_t id = 0;
        std::uint32_t target = 0;
        std::uint32_t current = 0;
    };
    struct DataSource {
        std::vector<std::int32_t> values;
        std::uint32_t points = 0;
    };
    /// One pending FC10 element write, checked before anything is applied.
    struct ElementWrite {
        std::uint16_t address = 0;
        std::vector<std::uint16_t> words;
    };

    // r6_registers.cpp: the register map.
    [[nodiscard]] std::optional<std::vector<std::uint16_t>> read_element(std::uint16_t address) const;
    [[nodiscard]] std::size_t writable_width(std::uint16_t address, std::size_t remaining) const;
    [[nodiscard]] std::optional<protocol::ExceptionCode> check_write(const ElementWrite& write) const;
    void apply_write(const ElementWrite& write);
    [[nodiscard]] bool board_exists(std::size_t board) const noexcept;

    // r6_model.cpp: functions, commands, motion.
    [[nodiscard]] protocol::Response dispatch(const protocol::Request& request);
    [[nodiscard]] protocol::Response read_registers(const protocol::ReadRegistersRequest& request) const;
    [[nodiscard]] protocol::Response write_registers(const protocol::WriteMultipleRegistersRequest& request);
    [[nodiscard]] protocol::Response write_single(const protocol::WriteSingleRegisterRequest& request);
    [[nodiscard]] protocol::Response read_coils(const protocol::ReadBitsRequest& request) const;
    [[nodiscard]] protocol::Response write_coil(const protocol::WriteSingleCoilRequest& request);
    void run_command(std::uint16_t address);
    void start();
    [[nodiscard]] Counter* find_counter(std::uint32_t id) noexcept;
    [[nodiscard]] const Counter* find_counter(std::uint32_t id) const noexcept;
    void step_motion(Clock::duration elapsed);
    void complete_cycle(std::int64_t cycle_ns);

    std::string version_;
    std::vector<Counter> counters_;
    std::uint32_t selected_counter_ = 0;
    std::uint16_t mode_ = 3;
    std::uint16_t io_boards_ = 1;
    std::array<std::uint32_t, board_count> inputs_{};
    std::array<std::uint32_t, board_count> outputs_{};
    std::uint16_t axis_count_ = 6;
    std::array<std::int32_t, max_axes> axes_{};
    std::uint16_t alarm_ = 0;
    std::uint64_t cycle_ms_ = 0;
    std::uint64_t last_cycle_ms_ = 0;
    std::uint16_t host_address_ = 1;
    bool moving_ = false;
    bool origin_set_ = true;
    bool single_cycle_ = false;
    std::uint16_t global_speed_ = 1000;
    std::vector<std::int32_t> parameters_;
    std::map<std::uint16_t, DataSource> sources_;
    std::uint16_t view_source_ = 100;
    std::uint16_t edit_source_ = 100;
    std::uint16_t edit_format_ = 6;
    std::uint16_t edit_mask_ = 0x3F;
    std::uint16_t upload_points_ = 0;
    std::uint16_t upload_clear_ = 0;

    /// Fault mode (control "malform KIND ADDRESS"): replies to requests starting at
    /// `malform_address_` are corrupted, to test a master's reply validation.
    enum class Malform : std::uint8_t { off, long_exception, extra_registers, byte_count };
    [[nodiscard]] protocol::Bytes malformed(protocol::ByteView request_pdu, protocol::Bytes reply) const;
    Malform malform_ = Malform::off;
    std::uint16_t malform_address_ = 0;

    // Motion: the sweep phase in thousandths of a degree of axis 0 and its remainder.
    std::int64_t phase_ = 0;
    std::int64_t phase_remainder_ = 0;  ///< units x ns not yet turned into a whole unit
    std::int64_t cycle_elapsed_ns_ = 0;
    Clock::time_point last_advance_{};
    bool clock_started_ = false;
};

}  // namespace fieldbridge::sim
