#include "config/sparkplug_ids.hpp"

#include "core/log_text.hpp"

namespace fieldbridge::config {

std::optional<std::string> sparkplug_id_problem(std::string_view id) {
    if (id.empty()) return "is empty";
    if (id.find_first_of("+/#") != std::string_view::npos) {
        return "contains +, / or #, which Sparkplug reserves (topic levels and wildcards)";
    }
    if (id.find('\0') != std::string_view::npos) return "contains a NUL character, which MQTT forbids in a topic";
    for (std::size_t i = 0; i < id.size();) {
        if (static_cast<unsigned char>(id[i]) < 0x80) {
            ++i;
            continue;
        }
        char32_t code = 0;
        const std::size_t length = core::log_text_detail::utf8_sequence(id, i, code);
        if (length == 0) return "is not valid UTF-8";
        i += length;
    }
    return std::nullopt;
}

}  // namespace fieldbridge::config
