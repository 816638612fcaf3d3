#include "daemon/check_config.hpp"

#include <netdb.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <ostream>

#include "config/diagnostic.hpp"
#include "daemon/config_summary.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/status_board.hpp"

namespace fieldbridge::daemon {

namespace {

/// The hosts of tcp:// line ports resolve now (the daemon resolves them at each
/// connect and logs a failure; here it is an error before the gateway is started).
/// Returns the number of problems written to @p err.
std::size_t check_line_hosts(const std::filesystem::path& file, const config::Config& config, std::ostream& err) {
    std::size_t problems = 0;
    for (const auto& line : config.lines) {
        if (!line.tcp || config::parse_ip_address(line.tcp->host)) continue;
        addrinfo hints{};
        hints.ai_family = AF_UNSPEC;
        hints.ai_socktype = SOCK_STREAM;
        addrinfo* found = nullptr;
        const int rc = ::getaddrinfo(line.tcp->host.c_str(), nullptr, &hints, &found);
        if (rc == 0) {
            ::freeaddrinfo(found);
            continue;
        }
        ++problems;
        err << file.string() << ": line '" << line.name << "': port " << line.port << ": host '" << line.tcp->host
            << "' does not resolve (" << (rc == EAI_SYSTEM ? std::strerror(errno) : ::gai_strerror(rc))
            << "); check the name, /etc/hosts and the DNS settings, or give the device server's IP address\n";
    }
    return problems;
}

}  // namespace

int check_config(const std::filesystem::path& file, const ConfigLoader& load, std::ostream& out, std::ostream& err) {
    try {
        const auto config = load(file);
        if (const std::size_t problems = check_line_hosts(file, *config, err); problems > 0) {
            err << file.string() << ": " << count_of(problems, "problem", "problems")
                << " found; the configuration is not valid\n";
            return exit_config_error;
        }
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
