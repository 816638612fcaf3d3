#pragma once
/// @file error.hpp
/// The project's one exception type (docs/architecture.md, "Two error channels"):
/// start-up, configuration and resource errors, and values a function cannot accept,
/// throw core::Error or a subclass. Per-frame outcomes are never exceptions.
///
/// An error is read by an operator, often at night, in the journal: it says what
/// failed, where (a file:line:col, a port, a line, a device, a listen address), and
/// what to do about it. what() is "where: what failed (what to do)", the parts that
/// are empty left out.

#include <stdexcept>
#include <string>
#include <utility>

namespace fieldbridge::core {

class Error : public std::runtime_error {
public:
    /// A message that already says everything (what failed, where, what to do).
    explicit Error(const std::string& message) : Error(message, std::string{}, std::string{}) {}
    /// @p failed: what failed, and why; @p where: what it concerns ("serial port
    /// /dev/ttyUSB0", "line bus1"); @p hint: what the operator can do (may be empty).
    Error(std::string failed, std::string where, std::string hint)
        : std::runtime_error(compose(failed, where, hint)),
          failed_(std::move(failed)),
          where_(std::move(where)),
          hint_(std::move(hint)) {}

    [[nodiscard]] const std::string& failed() const noexcept { return failed_; }
    [[nodiscard]] const std::string& where() const noexcept { return where_; }
    [[nodiscard]] const std::string& hint() const noexcept { return hint_; }

private:
    [[nodiscard]] static std::string compose(const std::string& failed, const std::string& where,
                                             const std::string& hint) {
        std::string text = where.empty() ? failed : where + ": " + failed;
        if (!hint.empty()) text += " (" + hint + ")";
        return text;
    }

    std::string failed_;
    std::string where_;
    std::string hint_;
};

/// A value a function or an encoder cannot accept: a setting outside its range, a
/// field the wire cannot carry. The project's replacement for std::invalid_argument.
class InvalidArgument : public Error {
public:
    using Error::Error;
};

}  // namespace fieldbridge::core
