#pragma once
/// @file temp_dir.hpp
/// Temporary directories for tests and benchmarks: one place that creates them
/// (mkdtemp: unique, mode 0700, never an existing directory) and removes them.
#include <filesystem>
#include <string_view>

namespace fieldbridge::test {

/// Creates a fresh directory "<temp dir>/<prefix>-<unique>" and returns its path.
/// Throws std::runtime_error with the OS error when it cannot.
[[nodiscard]] std::filesystem::path make_temp_dir(std::string_view prefix);

/// A temporary directory removed, with everything in it, when this goes.
class TempDir {
public:
    explicit TempDir(std::string_view prefix = "fieldbridge-test") : path_(make_temp_dir(prefix)) {}
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace fieldbridge::test
