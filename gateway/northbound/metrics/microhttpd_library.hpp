#pragma once
/// @file microhttpd_library.hpp
/// libmicrohttpd loaded with dlopen() when an endpoint starts, not linked: Debian's
/// libmicrohttpd12 is built with HTTPS and brings GnuTLS and eight more libraries
/// (about 2.5 MB of resident pages, docs/performance.md "Footprint"), which a daemon
/// without `metrics_http` has no use for. Only the functions the endpoint calls are
/// resolved; the declarations come from <microhttpd.h> (libmicrohttpd-dev), so the
/// pointers have the library's own types.
#include <memory>
#include <string>

#include <microhttpd.h>

namespace fieldbridge::northbound::metrics {

/// The library's run-time name: its SONAME, found at configure time
/// (northbound/metrics/CMakeLists.txt).
#ifndef FIELDBRIDGE_MICROHTTPD_SONAME
#error "FIELDBRIDGE_MICROHTTPD_SONAME: set by gateway/northbound/metrics/CMakeLists.txt"
#endif
inline constexpr const char* microhttpd_soname = FIELDBRIDGE_MICROHTTPD_SONAME;

/// The few MHD functions the endpoint uses.
struct MicrohttpdApi {
    decltype(&::MHD_start_daemon) start_daemon = nullptr;
    decltype(&::MHD_stop_daemon) stop_daemon = nullptr;
    decltype(&::MHD_get_daemon_info) get_daemon_info = nullptr;
    decltype(&::MHD_get_connection_info) get_connection_info = nullptr;
    decltype(&::MHD_get_timeout) get_timeout = nullptr;
    decltype(&::MHD_run) run = nullptr;
    decltype(&::MHD_create_response_from_buffer) create_response_from_buffer = nullptr;
    decltype(&::MHD_add_response_header) add_response_header = nullptr;
    decltype(&::MHD_queue_response) queue_response = nullptr;
    decltype(&::MHD_destroy_response) destroy_response = nullptr;
};

/// Loads @p library (a file name searched like any shared library, or a path) and
/// resolves the functions. Once loaded it stays loaded until the process exits (a
/// later call returns the same table): GnuTLS is not made to unload and reload on
/// every reload of the configuration. Throws MetricsHttpError, prefixed with
/// @p context, saying what failed (dlerror()'s text), which library, and what to do.
[[nodiscard]] const MicrohttpdApi& load_microhttpd(const std::string& library, const std::string& context);

}  // namespace fieldbridge::northbound::metrics
