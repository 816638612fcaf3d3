#pragma once
/// @file diagnostic_sink.hpp
/// Collects diagnostics while the loader runs, so every step reports all it finds.
/// Internal to the config layer.

#include <string>
#include <utility>
#include <vector>

#include "config/diagnostic.hpp"
#include "config/raw_config.hpp"

namespace fieldbridge::config {

class DiagnosticSink {
public:
    explicit DiagnosticSink(std::string file) : file_(std::move(file)) {}

    void error(Mark mark, std::string key, std::string message) {
        diagnostics_.push_back(Diagnostic{file_, mark.line, mark.column, std::move(key), std::move(message)});
    }
    template <class T>
    void error(const Field<T>& field, std::string message) {
        error(field.mark, field.path, std::move(message));
    }
    void error(const RawNode& node, std::string message) { error(node.mark, node.path, std::move(message)); }

    /// A problem found in another file (a device definition).
    void add(Diagnostic diagnostic) { diagnostics_.push_back(std::move(diagnostic)); }

    [[nodiscard]] bool empty() const noexcept { return diagnostics_.empty(); }
    [[nodiscard]] std::size_t size() const noexcept { return diagnostics_.size(); }
    [[nodiscard]] const std::string& file() const noexcept { return file_; }
    /// Sorted by position (stable, so problems at one position keep their order); the
    /// sink's own file first, then the other files' problems in the order they came.
    [[nodiscard]] std::vector<Diagnostic> take_sorted();

private:
    std::string file_;
    std::vector<Diagnostic> diagnostics_;
};

}  // namespace fieldbridge::config
