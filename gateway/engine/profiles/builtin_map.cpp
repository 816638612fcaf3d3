#include "engine/profiles/builtin_map.hpp"

#include <string>

#include "config/builtin_definitions.hpp"

namespace fieldbridge::engine {

std::shared_ptr<const RegisterMap> builtin_register_map(DeviceType type, const ProfileOptions& options) {
    std::vector<RegisterDef> rows = options.registers;
    if (rows.empty()) {
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
                               " is built into fieldbridge and none was given; install " +
                               std::string(to_string(type)) + ".yaml under /usr/share/fieldbridge/devices");
        }
        rows = definition->registers;
    }
    try {
        return std::make_shared<const RegisterMap>(std::move(rows));
    } catch (const core::Error& e) {
        throw ProfileError("the register map of " + std::string(to_string(type)) + " is unusable: " + e.what() +
                           "; fix registers: in its definition file");
    }
}

}  // namespace fieldbridge::engine
