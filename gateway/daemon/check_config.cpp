#include "daemon/check_config.hpp"

#include <ostream>

#include "config/diagnostic.hpp"
#include "daemon/config_summary.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/status_board.hpp"

namespace fieldbridge::daemon {

int check_config(const std::filesystem::path& file, const ConfigLoader& load, std::ostream& out, std::ostream& err) {
    try {
        const auto config = load(file);
        out << file.string() << ": configuration is valid (" << describe_config(*config) << ")\n";
        return exit_ok;
    } catch (const config::ConfigError& error) {
        for (const auto& diagnostic : error.diagnostics()) {
            err << diagnostic.to_string() << '\n';
        }
        err << file.string() << ": " << count_of(error.diagnostics().size(), "problem", "problems")
            << " found; the configuration is not valid\n";
        return exit_config_error;
    }
}

}  // namespace fieldbridge::daemon
