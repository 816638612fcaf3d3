#pragma once
/// @file status_board.hpp
/// The one-line STATUS= summary that `systemctl status fieldbridge` shows.

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace fieldbridge::daemon {

/// Returns one part of the summary ("2 lines up", "3 TCP clients"), or an empty
/// string when it has nothing to say right now.
using StatusContributor = std::function<std::string()>;

/// Joins the parts of every contributor, in registration order, with ", ", and
/// remembers what was last published so that an unchanged line is not sent again.
class StatusBoard {
public:
    /// systemd shows STATUS= on one line; a longer text is cut here (with "...").
    static constexpr std::size_t max_length = 200;

    void add(StatusContributor contributor);

    /// The current summary. A contributor that throws contributes
    /// "<status unavailable>": a bug in one component must not hide the others.
    [[nodiscard]] std::string compose() const;

    /// compose(), when it differs from what was last taken (or when @p force); the
    /// result is remembered as published. nullopt: nothing new to publish.
    [[nodiscard]] std::optional<std::string> take_if_changed(bool force = false);

private:
    std::vector<StatusContributor> contributors_;
    std::optional<std::string> published_;
};

/// "1 line", "2 lines": @p count followed by the singular or plural noun.
[[nodiscard]] std::string count_of(std::size_t count, const std::string& singular, const std::string& plural);

}  // namespace fieldbridge::daemon
