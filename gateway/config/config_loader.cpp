#include "config/config_loader.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include "config/build_config.hpp"
#include "config/definition_files.hpp"
#include "config/diagnostic_sink.hpp"
#include "config/raw_parse.hpp"
#include "config/validate.hpp"
#include "config/yaml_documents.hpp"

namespace fieldbridge::config {

namespace {

[[nodiscard]] std::filesystem::path absolute_directory_of(const std::filesystem::path& file) {
    std::error_code ec;
    auto absolute = std::filesystem::absolute(file, ec);
    if (ec) {
        absolute = file;
    }
    return absolute.parent_path();
}

/// YAML -> raw -> validate -> Config, collecting every problem before throwing.
[[nodiscard]] std::shared_ptr<const Config> load(std::string_view yaml, const std::string& file_name,
                                                 const std::filesystem::path& base_dir) {
    DiagnosticSink sink(file_name);
    YamlDocuments documents;
    try {
        documents = read_documents(yaml);
    } catch (const YAML::Exception& e) {
        // A syntax error stops the YAML parser: nothing after it can be read.
        sink.error(to_mark(e.mark, Mark{1, 1}), "", "YAML syntax error: " + e.msg + "; fix the YAML at this position");
        throw ConfigError(sink.take_sorted());
    }
    if (!documents.first || documents.first.IsNull()) {
        sink.error(Mark{1, 1}, "", "the configuration is empty; expected at least gateway: { id: <name> }");
        throw ConfigError(sink.take_sorted());
    }
    if (documents.second) {
        sink.error(to_mark(*documents.second, Mark{1, 1}), "",
                   "a second YAML document starts here (---); expected a single document");
    }
    RawConfig raw = parse_raw(documents.first, sink);
    resolve_definitions(raw, base_dir, sink);
    validate(raw, base_dir, sink);
    if (!sink.empty()) {
        throw ConfigError(sink.take_sorted());
    }
    Config config = build_config(raw, base_dir, file_name, sink);
    if (!sink.empty()) {
        throw ConfigError(sink.take_sorted());
    }
    return std::make_shared<const Config>(std::move(config));
}

}  // namespace

std::shared_ptr<const Config> load_config_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int error = errno;
        throw ConfigError({Diagnostic{path.string(), 0, 0, "",
                                      std::string("cannot open the configuration file: ") + std::strerror(error) +
                                          "; check the path and that the service user may read it"}});
    }
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) {
        throw ConfigError({Diagnostic{path.string(), 0, 0, "", "cannot read the configuration file; check the disk"}});
    }
    return load(text, path.string(), absolute_directory_of(path));
}

std::shared_ptr<const Config> load_config_string(std::string_view yaml, std::string file_name) {
    const auto base_dir = absolute_directory_of(std::filesystem::path(file_name));
    return load(yaml, file_name, base_dir);
}

}  // namespace fieldbridge::config
