#include "config/diagnostic.hpp"

#include <algorithm>

#include "config/diagnostic_sink.hpp"

namespace fieldbridge::config {

std::string Diagnostic::to_string() const {
    std::string out = file;
    if (line > 0) {
        out += ':' + std::to_string(line) + ':' + std::to_string(column);
    }
    out += ": ";
    if (!key.empty()) {
        out += key + ": ";
    }
    out += message;
    return out;
}

namespace {

[[nodiscard]] std::string join_lines(const std::vector<Diagnostic>& diagnostics) {
    std::string out;
    for (const auto& d : diagnostics) {
        if (!out.empty()) {
            out += '\n';
        }
        out += d.to_string();
    }
    return out;
}

}  // namespace

ConfigError::ConfigError(std::vector<Diagnostic> d) : core::Error(join_lines(d)), diagnostics_(std::move(d)) {}

std::vector<Diagnostic> DiagnosticSink::take_sorted() {
    std::stable_sort(diagnostics_.begin(), diagnostics_.end(), [this](const Diagnostic& a, const Diagnostic& b) {
        const bool a_other = a.file != file_;
        const bool b_other = b.file != file_;
        if (a_other || b_other) {
            return !a_other && b_other;  // another file's keep their order, after this file's
        }
        return a.line != b.line ? a.line < b.line : a.column < b.column;
    });
    return std::move(diagnostics_);
}

}  // namespace fieldbridge::config
