#pragma once
/// @file load_shape.hpp
/// The read load a line benchmark puts on a line, the same for the gateway and for
/// its floor (raw_master.hpp), and its frame sizes for the physical limit:
///
/// - `xeg`: one HIWIN XEG at bus address 2, FC04 0x0300 x2 (position + status);
///   writes FC16 of one register (the XEG profile sends FC06 as FC16): 11 + 8 bytes;
/// - `generic`: four generic `modbus` devices at bus addresses 1-4, FC03 x2 at
///   register addresses that vary over 0-99, the devices in turn; writes FC06: 8 + 8
///   bytes. The load of issue 14's independent harness.
///
/// Both reads are 8 + 9 bytes on the wire.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace fieldbridge::bench {

/// One read of a shape: to the device at @c device (0-based, in bus address order).
struct ShapeRead {
    std::size_t device = 0;
    std::uint8_t function = 0;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
};

class LoadShape {
public:
    enum class Kind : std::uint8_t { xeg, generic };

    explicit LoadShape(Kind kind) : kind_(kind) {}
    /// "xeg" or "generic"; throws std::invalid_argument otherwise.
    [[nodiscard]] static LoadShape parse(std::string_view name);

    [[nodiscard]] Kind kind() const noexcept { return kind_; }
    [[nodiscard]] std::string_view name() const noexcept;
    /// "1 HIWIN XEG, FC04 0x0300 x2" / "4 generic devices, FC03 x2 at 0-99".
    [[nodiscard]] std::string_view description() const noexcept;
    [[nodiscard]] std::size_t devices() const noexcept { return kind_ == Kind::xeg ? 1 : 4; }
    [[nodiscard]] std::uint8_t bus_address(std::size_t device) const noexcept;
    /// The @p n -th read of a sequence.
    [[nodiscard]] ShapeRead read(std::uint64_t n) const noexcept;
    /// The simulator's devices for one bus: "hiwin-xeg@2" / "modbus@1,modbus@2,...".
    [[nodiscard]] std::string sim_devices() const;
    /// The daemon's side of the same devices: entries of a line's `devices:` list (YAML,
    /// indented for it), Modbus TCP units from @p first_unit, every read to the line
    /// (max_age 0), a queue for 16 readers and the writes, no polling to speak of: one
    /// XEG `xeg-direct`, or `generic-<address>` with one block over every register the
    /// shape reads or writes.
    [[nodiscard]] std::string daemon_devices(std::uint8_t first_unit) const;
    /// The write a latency measurement sends: FC06 to this holding register (the XEG
    /// profile turns it into FC16), and its frame sizes on the line.
    [[nodiscard]] std::uint16_t write_register() const noexcept { return kind_ == Kind::xeg ? 0x0631 : 0x0010; }
    [[nodiscard]] std::size_t write_request_bytes() const noexcept { return kind_ == Kind::xeg ? 11 : 8; }
    [[nodiscard]] std::size_t write_reply_bytes() const noexcept { return 8; }
    [[nodiscard]] static constexpr std::size_t read_request_bytes() noexcept { return 8; }
    /// address, function, byte count, 2 x 2 bytes, CRC.
    [[nodiscard]] static constexpr std::size_t read_reply_bytes() noexcept { return 9; }

private:
    Kind kind_;
};

}  // namespace fieldbridge::bench
