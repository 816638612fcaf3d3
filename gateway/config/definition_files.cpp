#include "config/definition_files.hpp"

#include <cctype>
#include <fstream>
#include <iterator>
#include <map>
#include <system_error>

#include "config/device_definition.hpp"
#include "config/raw_parse.hpp"
#include "config/validate.hpp"
#include "config/yaml_documents.hpp"

namespace fieldbridge::config {

namespace {

/// A definition is a page of YAML; anything this large is not one.
constexpr std::uintmax_t max_definition_bytes = 1024 * 1024;

[[nodiscard]] std::string built_in_names() {
    std::string names;
    for (const auto& [name, type] : core::device_type_names) {
        names += (names.empty() ? "" : ", ") + std::string(name);
    }
    return names;
}

[[nodiscard]] std::string searched(const std::vector<std::filesystem::path>& dirs) {
    std::string out;
    for (const auto& dir : dirs) {
        std::error_code ec;
        out += (out.empty() ? "" : ", ") + dir.string() +
               (std::filesystem::is_directory(dir, ec) ? "" : " (no such directory)");
    }
    return out;
}

/// " (did you mean 'hiwin-xeg'?)" for a built-in type spelled with other case or '_'.
[[nodiscard]] std::string built_in_hint(std::string_view name) {
    std::string folded(name);
    for (char& c : folded) {
        c = c == '_' ? '-' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    for (const auto& [built_in, type] : core::device_type_names) {
        if (folded == built_in) {
            return " (did you mean '" + std::string(built_in) + "'?)";
        }
    }
    return "";
}

struct Lookup {
    std::shared_ptr<const RawDefinition> definition;  ///< null: not found or with problems
    std::string file;                                 ///< "" when not found
};

using Lookups = std::map<std::string, Lookup, std::less<>>;

/// The definition @p name in @p dirs, read once per name (its problems reported once).
Lookups::const_iterator look_up(const std::string& name, const std::vector<std::filesystem::path>& dirs,
                                Lookups& read, DiagnosticSink& sink) {
    auto it = read.find(name);
    if (it == read.end()) {
        Lookup lookup;
        if (const auto file = find_definition(name, dirs)) {
            std::vector<Diagnostic> problems;
            lookup.file = std::filesystem::absolute(*file).lexically_normal().string();
            lookup.definition = read_definition(lookup.file, problems);
            for (auto& problem : problems) {
                sink.add(std::move(problem));
            }
        }
        it = read.emplace(name, std::move(lookup)).first;
    }
    return it;
}

/// A built-in type's definition file in @p dirs replaces the compiled-in one
/// (docs/devices.md, "Built-in types"); without one the device keeps no definition
/// and the engine uses the compiled-in copy.
void resolve_builtin(RawDevice& device, const std::vector<std::filesystem::path>& dirs, Lookups& read,
                     DiagnosticSink& sink) {
    const std::string& name = *device.type_name;
    const auto it = look_up(name, dirs, read, sink);
    if (it->second.file.empty()) {
        return;
    }
    const auto& definition = it->second.definition;
    if (definition == nullptr) {
        sink.error(device.type_name, "the device definition " + it->second.file + " replaces the built-in " + name +
                                         " and has problems (listed under its name); fix them, or remove the file "
                                         "to use the definition built into fieldbridge");
        device.type.invalid = true;
        device.type.value.reset();
    } else if (definition->behaviour.value_or(DeviceType::modbus) != *device.type) {
        sink.error(device.type_name, "the device definition " + it->second.file + " replaces the built-in " + name +
                                         " but does not name its behaviour; expected behaviour: " + name +
                                         " in it (or remove the file to use the definition built into fieldbridge)");
        device.type.invalid = true;
        device.type.value.reset();
    } else {
        device.definition = definition;
    }
}

}  // namespace

std::vector<std::filesystem::path> definition_dirs(const RawConfig& raw, const std::filesystem::path& base_dir) {
    std::vector<std::filesystem::path> dirs;
    if (!raw.definitions.absent()) {
        for (const auto& item : raw.definitions.items) {
            if (item.has_value() && !item->empty()) {
                dirs.push_back(resolve_path(base_dir, *item));
            }
        }
        return dirs;
    }
    for (const auto dir : default_definition_dirs) {
        dirs.emplace_back(dir);
    }
    return dirs;
}

std::optional<std::filesystem::path> find_definition(std::string_view name,
                                                     const std::vector<std::filesystem::path>& dirs) {
    for (const auto& dir : dirs) {
        std::error_code ec;
        auto file = dir / (std::string(name) + ".yaml");
        if (std::filesystem::is_regular_file(file, ec)) {
            return file.lexically_normal();
        }
    }
    return std::nullopt;
}

std::shared_ptr<const RawDefinition> parse_definition_text(std::string_view text, const std::string& file,
                                                           std::string_view stem, std::vector<Diagnostic>& problems) {
    DiagnosticSink sink(file);
    YamlDocuments documents;
    try {
        documents = read_documents(std::string(text));
    } catch (const YAML::Exception& e) {
        sink.error(to_mark(e.mark, Mark{1, 1}), "", "YAML syntax error: " + e.msg + "; fix the YAML at this position");
    }
    if (sink.empty() && (!documents.first || documents.first.IsNull())) {
        sink.error(Mark{1, 1}, "", "the device definition is empty; expected at least name: and points:");
    } else if (sink.empty()) {
        if (documents.second) {
            sink.error(to_mark(*documents.second, Mark{1, 1}), "",
                       "a second YAML document starts here (---); expected a single document");
        }
        auto definition = std::make_shared<RawDefinition>(parse_definition(documents.first, file, sink));
        if (definition->ok()) {
            validate_definition(*definition, stem, sink);
        }
        if (sink.empty()) {
            return definition;
        }
    }
    for (auto& d : sink.take_sorted()) {
        problems.push_back(std::move(d));
    }
    return nullptr;
}

std::shared_ptr<const RawDefinition> read_definition(const std::filesystem::path& file,
                                                     std::vector<Diagnostic>& problems) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    std::ifstream in(file, std::ios::binary);
    if (ec || !in) {
        problems.push_back(Diagnostic{file.string(), 0, 0, "",
                                      "cannot read the device definition file; check that it exists and that the "
                                      "service user may read it"});
        return nullptr;
    }
    if (size > max_definition_bytes) {
        problems.push_back(Diagnostic{file.string(), 0, 0, "",
                                      "the file is " + std::to_string(size) + " bytes; a device definition is at most " +
                                          std::to_string(max_definition_bytes) + " bytes: is it the right file?"});
        return nullptr;
    }
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return parse_definition_text(text, file.string(), file.stem().string(), problems);
}

void resolve_definitions(RawConfig& raw, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    for (const auto& dir : raw.definitions.items) {
        if (dir.has_value() && dir->empty()) {
            sink.error(dir, "an empty directory name; expected a directory of device definition files");
        }
    }
    const auto dirs = definition_dirs(raw, base_dir);
    Lookups read;
    for (auto& line : raw.lines.items) {
        for (auto& device : line.devices.items) {
            if (!device.ok() || !device.type_name.has_value()) {
                continue;
            }
            if (device.type.has_value()) {
                if (*device.type != DeviceType::modbus) {
                    resolve_builtin(device, dirs, read, sink);
                }
                continue;
            }
            const std::string& name = *device.type_name;
            device.type.invalid = true;  // until a valid definition is found
            if (!is_definition_name(name)) {
                sink.error(device.type_name, "'" + name + "' is neither a built-in type" + built_in_hint(name) +
                                                 " (" + built_in_names() +
                                                 ") nor a device definition name (a-z 0-9 _ -, starting with a "
                                                 "letter or digit, up to 64 characters)");
                continue;
            }
            const auto it = look_up(name, dirs, read, sink);
            if (it->second.file.empty()) {
                sink.error(device.type_name, "'" + name + "' is not a built-in type" + built_in_hint(name) + " (" +
                                                 built_in_names() +
                                                 ") and no device definition " + name + ".yaml was found; searched, "
                                                 "in this order: " + searched(dirs) +
                                                 "; install the definition there or set definitions: in the "
                                                 "configuration");
            } else if (it->second.definition == nullptr) {
                sink.error(device.type_name, "the device definition " + it->second.file +
                                                 " has problems (listed under its name); fix them");
            } else {
                device.definition = it->second.definition;
                // A site's variant of a built-in type (behaviour:) is that type.
                device.type.value = it->second.definition->behaviour.value_or(DeviceType::modbus);
                device.type.invalid = false;
            }
        }
    }
}

}  // namespace fieldbridge::config
