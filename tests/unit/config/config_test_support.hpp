#pragma once
// Helpers for the configuration tests: load inline YAML, look for a diagnostic by
// key path and check its position and message.

#include <doctest/doctest.h>

#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config_loader.hpp"

namespace fieldbridge::config::test {

/// R"(...)" literals in the tests start with a newline; drop it so that the first
/// line of the YAML is line 1.
inline std::string yaml_text(std::string_view text) {
    if (!text.empty() && text.front() == '\n') {
        text.remove_prefix(1);
    }
    return std::string(text);
}

/// The diagnostics of loading @p yaml; empty when it loaded.
inline std::vector<Diagnostic> diagnostics_of(std::string_view yaml, const std::string& file = "test.yaml") {
    try {
        (void)load_config_string(yaml_text(yaml), file);
        return {};
    } catch (const ConfigError& e) {
        return e.diagnostics();
    }
}

/// A configuration of one line with one device `d` of @p type at address 3, unit 1:
/// @p top first (top-level keys), then the device, whose keys end on line 9 (plus
/// the lines of @p top); @p extra continues the device (at its indentation, 8 spaces).
inline std::string one_device_config(std::string_view type, std::string_view extra = "", std::string_view top = "") {
    return std::string(top) +
           "gateway: {id: t}\n"
           "lines:\n"
           "  - name: a\n"
           "    port: /dev/ttyS0\n"
           "    devices:\n"
           "      - name: d\n"
           "        type: " + std::string(type) + "\n"
           "        address: 3\n"
           "        unit_id: 1\n" + std::string(extra);
}

inline std::string dump(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    for (const auto& d : diagnostics) {
        out += d.to_string() + "\n";
    }
    return out.empty() ? "(no diagnostics)" : out;
}

inline std::optional<Diagnostic> find_diagnostic(const std::vector<Diagnostic>& diagnostics, std::string_view key) {
    for (const auto& d : diagnostics) {
        if (d.key == key) {
            return d;
        }
    }
    return std::nullopt;
}

/// Loads @p yaml and requires success.
inline std::shared_ptr<const Config> load_ok(std::string_view yaml, const std::string& file = "test.yaml") {
    try {
        return load_config_string(yaml_text(yaml), file);
    } catch (const ConfigError& e) {
        FAIL("expected the config to load, got:\n" << e.what());
    }
    return nullptr;
}

/// Requires a diagnostic for @p key at @p line : @p column whose message contains
/// every fragment.
inline void check_reports(std::string_view yaml, std::string_view key, int line, int column,
                          std::initializer_list<std::string_view> fragments) {
    const auto diagnostics = diagnostics_of(yaml);
    INFO("diagnostics:\n" << dump(diagnostics));
    const auto found = find_diagnostic(diagnostics, key);
    REQUIRE_MESSAGE(found.has_value(), "no diagnostic for key '" << std::string(key) << "'");
    CHECK(found->file == "test.yaml");
    CHECK(found->line == line);
    CHECK(found->column == column);
    for (const auto fragment : fragments) {
        CHECK_MESSAGE(found->message.find(fragment) != std::string::npos,
                      "message lacks '" << std::string(fragment) << "'");
    }
}

}  // namespace fieldbridge::config::test

/// check_reports() with the calling line in the failure report.
#define CHECK_REPORTS(yaml, key, line, column, ...)                                                   \
    do {                                                                                              \
        INFO("checked at line " << __LINE__);                                                         \
        ::fieldbridge::config::test::check_reports(yaml, key, line, column, {__VA_ARGS__});           \
    } while (false)
