#include "northbound/metrics/microhttpd_library.hpp"

#include <dlfcn.h>

#include <map>
#include <mutex>

#include <fmt/format.h>

#include "northbound/metrics/http_endpoint.hpp"

namespace fieldbridge::northbound::metrics {

namespace {

/// dlerror()'s text, or @p fallback when it has none.
[[nodiscard]] std::string last_dl_error(const char* fallback) {
    const char* text = ::dlerror();
    return text != nullptr ? text : fallback;
}

template <typename Function>
void resolve(void* handle, const char* name, Function& function, const std::string& library,
             const std::string& context) {
    ::dlerror();  // clear
    void* symbol = ::dlsym(handle, name);
    if (symbol == nullptr) {
        throw MetricsHttpError(fmt::format(
            "{}: {} has no {} ({}); it is not the libmicrohttpd this build expects: install Debian's "
            "(`apt install libmicrohttpd12` on Debian 12, libmicrohttpd12t64 on Debian 13), or remove the "
            "metrics_http section",
            context, library, name, last_dl_error("symbol not found")));
    }
    function = reinterpret_cast<Function>(symbol);
}

}  // namespace

const MicrohttpdApi& load_microhttpd(const std::string& library, const std::string& context) {
    static std::mutex mutex;
    static std::map<std::string, MicrohttpdApi> loaded;  // never unloaded (see the header)
    const std::lock_guard lock(mutex);
    if (const auto found = loaded.find(library); found != loaded.end()) return found->second;

    void* handle = ::dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
        throw MetricsHttpError(fmt::format(
            "{}: cannot load the HTTP library {} ({}); the fieldbridge package depends on it: reinstall it "
            "(`apt install libmicrohttpd12` on Debian 12, libmicrohttpd12t64 on Debian 13), or remove the "
            "metrics_http section to serve no metrics",
            context, library, last_dl_error("dlopen failed")));
    }
    MicrohttpdApi api;
    try {
        resolve(handle, "MHD_start_daemon", api.start_daemon, library, context);
        resolve(handle, "MHD_stop_daemon", api.stop_daemon, library, context);
        resolve(handle, "MHD_get_daemon_info", api.get_daemon_info, library, context);
        resolve(handle, "MHD_get_connection_info", api.get_connection_info, library, context);
        resolve(handle, "MHD_get_timeout", api.get_timeout, library, context);
        resolve(handle, "MHD_run", api.run, library, context);
        resolve(handle, "MHD_create_response_from_buffer", api.create_response_from_buffer, library, context);
        resolve(handle, "MHD_add_response_header", api.add_response_header, library, context);
        resolve(handle, "MHD_queue_response", api.queue_response, library, context);
        resolve(handle, "MHD_destroy_response", api.destroy_response, library, context);
    } catch (...) {
        ::dlclose(handle);
        throw;
    }
    return loaded.emplace(library, api).first->second;
}

}  // namespace fieldbridge::northbound::metrics
