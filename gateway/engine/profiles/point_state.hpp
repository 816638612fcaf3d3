#pragma once
/// @file point_state.hpp
/// The state fields and alarms that points make of a register image (docs/devices.md):
/// one field per point in engineering units (an enum point: its label and
/// `<name>_code`; a `format: hex` point: its registers as a text), and the points'
/// alarm rules with hysteresis. Generic devices decode with it, and so do the
/// built-in types whose definition names their state as points.

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "core/point.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"

namespace fieldbridge::engine {

class PointState {
public:
    /// @p model as the configuration checked it: every alarm names one of its points.
    explicit PointState(core::PointModel model);
    PointState(const PointState&) = delete;
    PointState& operator=(const PointState&) = delete;

    [[nodiscard]] const core::PointModel& model() const noexcept { return model_; }
    /// The registers of point @p index from the image; empty when one is unknown.
    [[nodiscard]] std::vector<std::uint16_t> registers_of(const RegisterImage& image, std::size_t index) const;
    /// A field for every point whose registers are all known, in the model's order.
    [[nodiscard]] DecodedState decode(const RegisterImage& image) const;
    /// The raised rules. Hysteresis needs what was raised at the last call: that memory
    /// is this object's (one per device), guarded by a mutex.
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const;

private:
    core::PointModel model_;
    std::vector<std::size_t> alarm_points_;  ///< per alarm rule: the index of its point
    mutable std::mutex mutex_;
    mutable std::vector<bool> raised_;  ///< per alarm rule: raised at the last alarms()
};

}  // namespace fieldbridge::engine
