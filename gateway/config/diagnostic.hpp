#pragma once
/// @file diagnostic.hpp
/// Configuration problems: one Diagnostic per problem, all of them carried by one
/// ConfigError (the loader never stops at the first).

#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace fieldbridge::config {

struct Diagnostic {
    std::string file;
    int line = 0;    ///< 1-based; 0 when the problem has no position (file unreadable)
    int column = 0;  ///< 1-based
    std::string key;  ///< full key path, e.g. "lines[0].devices[2].address"; empty for YAML syntax
    std::string message;  ///< what is wrong, what was expected

    /// "file:line:col: key: message" (the parts without a value are left out).
    [[nodiscard]] std::string to_string() const;
    bool operator==(const Diagnostic&) const = default;
};

/// Thrown by the loader. what() lists every diagnostic, one per line.
class ConfigError : public core::Error {
public:
    explicit ConfigError(std::vector<Diagnostic> d);
    [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const noexcept { return diagnostics_; }

private:
    std::vector<Diagnostic> diagnostics_;
};

}  // namespace fieldbridge::config
