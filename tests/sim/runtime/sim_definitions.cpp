// fieldbridge-sim devices from device definition files: the search of --definition
// files and --definitions directories, and the definition as the model needs it.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string_view>

#include "config/device_definition.hpp"
#include "sim_error.hpp"
#include "sim_options.hpp"

namespace fieldbridge::sim::runtime {
namespace {

[[nodiscard]] std::shared_ptr<const DefinitionSpec> spec_of(const config::DeviceDefinition& definition) {
    auto spec = std::make_shared<DefinitionSpec>();
    spec->name = definition.name;
    spec->points = definition.points;
    for (const auto& block : definition.blocks) {
        spec->blocks.push_back(TableSpan{block.table, block.address, block.count});
    }
    return spec;
}

[[nodiscard]] std::string searched(const std::vector<std::string>& dirs, const std::vector<std::string>& files) {
    std::string out;
    for (const auto& file : files) out += (out.empty() ? "" : ", ") + file;
    for (const auto& dir : dirs) out += (out.empty() ? "" : ", ") + dir + "/";
    return out.empty() ? "nothing (give --definitions DIR or --definition FILE)" : out;
}

}  // namespace

void attach_definitions(std::vector<BusSpec>& buses, const std::vector<std::string>& dirs,
                        const std::vector<std::string>& files) {
    const auto built_in = device_types();
    std::vector<std::filesystem::path> dir_paths(dirs.begin(), dirs.end());
    std::map<std::string, std::shared_ptr<const DefinitionSpec>, std::less<>> loaded;
    for (auto& bus : buses) {
        for (auto& device : bus.devices) {
            if (std::find(built_in.begin(), built_in.end(), device.type) != built_in.end()) continue;
            auto it = loaded.find(device.type);
            if (it == loaded.end()) {
                std::optional<std::filesystem::path> file;
                for (const auto& candidate : files) {
                    if (std::filesystem::path(candidate).filename() == device.type + ".yaml") {
                        file = candidate;
                        break;
                    }
                }
                if (!file) file = config::find_definition(device.type, dir_paths);
                if (!file) {
                    throw SimError(fmt::format("--bus {}: device {}@{}: '{}' is not a built-in type ({}) and no "
                                               "definition {}.yaml was found; searched: {}",
                                               bus.name, device.type, device.address, device.type,
                                               fmt::join(built_in, ", "), device.type, searched(dirs, files)));
                }
                config::DeviceDefinition definition;
                try {
                    definition = config::load_definition_file(*file);
                } catch (const config::ConfigError& e) {
                    throw SimError(fmt::format("--bus {}: device {}@{}: the definition has problems:\n{}", bus.name,
                                               device.type, device.address, e.what()));
                }
                if (definition.behaviour) {
                    // A site's variant of a built-in type: the simulator's model of that type.
                    const std::string_view type = core::to_string(*definition.behaviour);
                    throw SimError(fmt::format("--bus {}: device {}@{}: {} is a variant of the built-in type {} "
                                               "(behaviour: {}); simulate it as {}@{}",
                                               bus.name, device.type, device.address, file->string(), type, type,
                                               type, device.address));
                }
                it = loaded.emplace(device.type, spec_of(definition)).first;
            }
            device.options.definition = it->second;
        }
    }
}

}  // namespace fieldbridge::sim::runtime
