#include "engine/profiles/profile_factory.hpp"

#include <string>

#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/generic_profile.hpp"
#include "engine/profiles/wtec_ascii_profile.hpp"
#include "engine/profiles/wtec_rtu_profile.hpp"
#include "engine/profiles/xeg_profile.hpp"

namespace fieldbridge::engine {

std::unique_ptr<DeviceProfile> make_profile(DeviceType type, const ProfileOptions& options) {
    switch (type) {
        case DeviceType::hiwin_xeg: return std::make_unique<XegProfile>(options);
        case DeviceType::excd203mb: return std::make_unique<ExcdProfile>(options);
        case DeviceType::wtec_rtu: return std::make_unique<WtecRtuProfile>(options);
        case DeviceType::wtec_ascii: return std::make_unique<WtecAsciiProfile>(options);
        case DeviceType::modbus: return std::make_unique<GenericProfile>(options);
    }
    throw ProfileError("unknown device type " + std::to_string(static_cast<int>(type)));
}

}  // namespace fieldbridge::engine
