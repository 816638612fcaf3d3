#include "temp_dir.hpp"

#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace fieldbridge::test {

std::filesystem::path make_temp_dir(std::string_view prefix) {
    // mkdtemp(3) replaces the template's six trailing 'X' with a unique suffix.
    const std::string unique_suffix(6, 'X');
    std::string pattern =
        (std::filesystem::temp_directory_path() / (std::string(prefix) + "-" + unique_suffix)).string();
    if (::mkdtemp(pattern.data()) == nullptr) {
        throw std::runtime_error("cannot create a temporary directory " + pattern + ": " + std::strerror(errno));
    }
    return pattern;
}

}  // namespace fieldbridge::test
