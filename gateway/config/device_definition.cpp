#include "config/device_definition.hpp"

#include <algorithm>
#include <set>
#include <system_error>

#include "config/build_points.hpp"
#include "config/definition_files.hpp"

namespace fieldbridge::config {

DeviceDefinition load_definition_file(const std::filesystem::path& file) {
    std::error_code ec;
    auto absolute = std::filesystem::absolute(file, ec);
    if (ec) absolute = file;
    std::vector<Diagnostic> problems;
    const auto raw = read_definition(absolute.lexically_normal(), problems);
    if (raw == nullptr) {
        throw ConfigError(std::move(problems));
    }
    return build_definition(*raw);
}

std::vector<DeviceDefinition> load_definitions(const std::vector<std::filesystem::path>& dirs,
                                               std::vector<Diagnostic>& problems) {
    std::vector<DeviceDefinition> definitions;
    std::set<std::string, std::less<>> names;
    for (const auto& dir : dirs) {
        std::error_code ec;
        std::vector<std::filesystem::path> files;
        for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
            if (entry.path().extension() == ".yaml" && entry.is_regular_file(ec)) {
                files.push_back(entry.path());
            }
        }
        std::sort(files.begin(), files.end());
        for (const auto& file : files) {
            if (!names.insert(file.stem().string()).second) {
                continue;  // an earlier directory has this name
            }
            const auto absolute = std::filesystem::absolute(file, ec).lexically_normal();
            if (const auto raw = read_definition(absolute, problems)) {
                definitions.push_back(build_definition(*raw));
            }
        }
    }
    return definitions;
}

}  // namespace fieldbridge::config
