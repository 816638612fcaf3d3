// The configuration loader (config/config_loader.hpp, load_config_string: the same
// YAML -> raw -> validate -> Config path as load_config_file) on arbitrary text.
// It either returns a Config or throws ConfigError with at least one diagnostic;
// anything else escaping (another exception, a crash) is a bug: the daemon reports
// ConfigError to the operator and exits cleanly.
// Input: the YAML text.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "config/config_loader.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace config = fieldbridge::config;
    const std::string_view yaml(reinterpret_cast<const char*>(data), size);
    try {
        // A directory that does not exist: relative TLS and password files resolve
        // against it and are never found, so the harness reads no file of the machine.
        const auto loaded = config::load_config_string(yaml, "/nonexistent-fieldbridge-fuzz/fuzz.yaml");
        FB_FUZZ_CHECK(loaded != nullptr);
    } catch (const config::ConfigError& error) {
        FB_FUZZ_CHECK(!error.diagnostics().empty());
        for (const auto& diagnostic : error.diagnostics()) {
            FB_FUZZ_CHECK(!diagnostic.message.empty());
        }
    }
    return 0;
}
