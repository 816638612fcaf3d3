#include "config/builtin_definitions.hpp"

#include <map>
#include <string>

#include "config/build_points.hpp"
#include "config/definition_files.hpp"

namespace fieldbridge::config {

namespace {

/// Every compiled-in definition, read and checked.
[[nodiscard]] std::map<DeviceType, DeviceDefinition> read_builtins() {
    std::map<DeviceType, DeviceDefinition> out;
    std::vector<Diagnostic> problems;
    for (const BuiltinText& builtin : builtin_definition_texts()) {
        const auto raw = parse_definition_text(builtin.text, builtin_definition_path(builtin.name), builtin.name,
                                               problems);
        if (raw != nullptr) {
            DeviceDefinition definition = build_definition(*raw);
            if (!definition.behaviour) {
                problems.push_back(Diagnostic{definition.file, 1, 1, "behaviour",
                                              "a built-in type's definition names its behaviour hook; expected "
                                              "behaviour: " + std::string(builtin.name)});
                continue;
            }
            out.emplace(*definition.behaviour, std::move(definition));
        }
    }
    if (!problems.empty()) {
        throw ConfigError(std::move(problems));
    }
    return out;
}

}  // namespace

std::string builtin_definition_path(std::string_view name) {
    return "(built in)/" + std::string(name) + ".yaml";
}

const DeviceDefinition* builtin_definition(DeviceType type) {
    // Read once, on first use, and immutable after: the compiled-in text cannot change.
    static const std::map<DeviceType, DeviceDefinition> builtins = read_builtins();
    const auto it = builtins.find(type);
    return it == builtins.end() ? nullptr : &it->second;
}

}  // namespace fieldbridge::config
