#include "engine/profiles/builtin_map.hpp"

#include <string>

#include "config/builtin_definitions.hpp"

namespace fieldbridge::engine {

namespace {

/// The compiled-in definition of @p type; throws ProfileError when there is none or
/// it has problems (a broken build).
[[nodiscard]] const config::DeviceDefinition& compiled_definition(DeviceType type) {
    const config::DeviceDefinition* definition = nullptr;
    try {
        definition = config::builtin_definition(type);
    } catch (const config::ConfigError& e) {
        throw ProfileError(std::string("the definition of ") + std::string(to_string(type)) +
                           " built into fieldbridge has problems (" + e.what() +
                           "); this build is broken: install a released package");
    }
    if (definition == nullptr) {
        throw ProfileError("no definition of " + std::string(to_string(type)) +
                           " is built into fieldbridge and none was given; install " + std::string(to_string(type)) +
                           ".yaml under /usr/share/fieldbridge/devices");
    }
    return *definition;
}

}  // namespace

std::shared_ptr<const RegisterMap> builtin_register_map(DeviceType type, const ProfileOptions& options) {
    std::vector<RegisterDef> rows = options.registers.empty() ? compiled_definition(type).registers : options.registers;
    try {
        return std::make_shared<const RegisterMap>(std::move(rows));
    } catch (const core::Error& e) {
        throw ProfileError("the register map of " + std::string(to_string(type)) + " is unusable: " + e.what() +
                           "; fix registers: in its definition file");
    }
}

core::PointModel builtin_state_points(DeviceType type, const ProfileOptions& options) {
    return options.builtin_state ? *options.builtin_state : compiled_definition(type).points;
}

}  // namespace fieldbridge::engine
