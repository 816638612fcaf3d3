#pragma once
/// @file modbus_profile.hpp
/// The behaviour every Modbus-RTU profile shares (XEG, EXCD203MB, WTEC in RTU mode,
/// generic): validation and classification from a RegisterMap, the function-code
/// translations a device needs on the wire, word order of 32-bit pairs, applying
/// replies to the image and answering the client. Concrete profiles give the map,
/// their function codes, what to poll, and the decoding.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

/// How northbound function codes map to the wire.
struct WireFunctions {
    std::vector<core::FunctionCode> northbound;  ///< accepted from clients (others: 0x01)
    bool fc06_as_fc16 = false;  ///< the device lacks FC06: send FC16 with one register
    bool fc16_as_fc06 = false;  ///< the device lacks FC16: send one FC06 per register
};

class ModbusProfile : public DeviceProfile {
public:
    [[nodiscard]] Bus bus() const noexcept override { return Bus::modbus_rtu; }
    [[nodiscard]] core::BusAddress broadcast_address() const noexcept override { return core::BusAddress{0}; }

    [[nodiscard]] std::optional<protocol::ExceptionCode> validate(const protocol::Request& request,
                                                                  const RegisterImage& image) const override;
    [[nodiscard]] Classification classify(const protocol::Request& request) const override;
    [[nodiscard]] std::vector<Payload> to_line(const protocol::Request& request,
                                               const RegisterImage& image) const override;
    [[nodiscard]] PollPlan poll_plan() const override;
    [[nodiscard]] ApplyResult apply(const Payload& sent, const Reply& reply, RegisterImage& image,
                                    TimePoint now) const override;
    [[nodiscard]] protocol::Response respond(const protocol::Request& request, std::span<const Reply> replies,
                                             const RegisterImage& image) const override;

    [[nodiscard]] const RegisterMap& map() const noexcept { return *map_; }
    [[nodiscard]] const ProfileOptions& options() const noexcept { return options_; }

protected:
    ModbusProfile(std::shared_ptr<const RegisterMap> map, WireFunctions wire, ProfileOptions options,
                  WordOrder word_order);

    /// Value checks beyond the map's min / max (default: none).
    [[nodiscard]] virtual std::optional<protocol::ExceptionCode> check_value(const RegisterDef& def,
                                                                             std::uint16_t unit_address,
                                                                             std::int64_t value,
                                                                             const RegisterImage& image) const;
    /// What to poll, before merging.
    [[nodiscard]] virtual std::vector<PollUnit> poll_units() const = 0;
    /// A device exception to @p sent (default: nothing more).
    virtual void on_device_exception(const protocol::Request& sent, protocol::ExceptionCode code,
                                     ApplyResult& result) const;
    /// A reply the shared code does not handle (FC07): default not_applicable.
    virtual void apply_other(const protocol::Request& sent, const protocol::Response& reply,
                             RegisterImage& image, TimePoint now, ApplyResult& result) const;

    /// Poll units for @p span from the map.
    [[nodiscard]] std::vector<PollUnit> units_for(Table table, std::uint16_t address, std::uint16_t count,
                                                  PollClass poll_class, bool motion = false) const;
    /// The period of a poll class from the options (0 for startup).
    [[nodiscard]] Duration period_of(PollClass poll_class) const noexcept;

private:
    /// Swaps the words of every whole pair of @p values (at @p address) in place;
    /// the words of a pair cut by either edge are flagged in @p partial.
    void swap_pairs(Table table, std::uint16_t address, std::span<std::uint16_t> values,
                    std::vector<bool>* partial) const;
    /// Stores @p values read or written at @p address in northbound order.
    void store(RegisterImage& image, Table table, std::uint16_t address, std::vector<std::uint16_t> values,
               bool wire_order, bool written, TimePoint now) const;
    [[nodiscard]] bool swaps() const noexcept { return word_order_ == WordOrder::low_first; }

    std::shared_ptr<const RegisterMap> map_;
    WireFunctions wire_;
    ProfileOptions options_;
    WordOrder word_order_;
};

}  // namespace fieldbridge::engine
