#include "daemon/status_board.hpp"

#include <utility>

namespace fieldbridge::daemon {

void StatusBoard::add(StatusContributor contributor) { contributors_.push_back(std::move(contributor)); }

std::string StatusBoard::compose() const {
    std::string line;
    for (const auto& contributor : contributors_) {
        std::string part;
        try {
            part = contributor();
        } catch (...) {
            part = "<status unavailable>";
        }
        // The summary is one line: a newline would end the STATUS= assignment and
        // start a bogus one in the notification.
        for (auto& c : part) {
            if (c == '\n' || c == '\r') {
                c = ' ';
            }
        }
        if (part.empty()) {
            continue;
        }
        if (!line.empty()) {
            line += ", ";
        }
        line += part;
    }
    if (line.size() > max_length) {
        line.resize(max_length - 3);
        line += "...";
    }
    return line;
}

std::optional<std::string> StatusBoard::take_if_changed(bool force) {
    std::string line = compose();
    if (!force && published_ == line) {
        return std::nullopt;
    }
    published_ = line;
    return line;
}

std::string count_of(std::size_t count, const std::string& singular, const std::string& plural) {
    return std::to_string(count) + ' ' + (count == 1 ? singular : plural);
}

}  // namespace fieldbridge::daemon
