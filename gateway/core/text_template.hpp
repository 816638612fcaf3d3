#pragma once
/// @file text_template.hpp
/// The text templates of points (docs/devices.md, "Texts from registers"): literal
/// text with placeholders `{name}` or `{name:hex}`, and `{{` / `}}` for a brace. A
/// point's `format:` template names its registers `{0}`, `{1}`, ...; an `enum_other:`
/// label names the code `{value}`. The configuration checks a template once
/// (template_error); the engine expands it at every decode (expand_template).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace fieldbridge::core {

/// One placeholder: its name and whether `:hex` asks for "0x" and upper-case digits.
struct TemplateSlot {
    std::string_view name;
    bool hex = false;
};

/// Calls @p literal(text) and @p slot(TemplateSlot) in order; returns what is wrong
/// with @p text (a brace left open or alone, an empty name, a style other than hex),
/// nullopt when the whole text was walked.
template <class Literal, class Slot>
[[nodiscard]] std::optional<std::string> walk_template(std::string_view text, Literal&& literal, Slot&& slot) {
    std::size_t i = 0;
    while (i < text.size()) {
        const char c = text[i];
        if ((c == '{' || c == '}') && i + 1 < text.size() && text[i + 1] == c) {
            literal(text.substr(i, 1));
            i += 2;
            continue;
        }
        if (c == '}') {
            return "a '}' at character " + std::to_string(i + 1) + " closes nothing; write '}}' for a brace";
        }
        if (c != '{') {
            const std::size_t next = text.find_first_of("{}", i);
            const std::size_t end = next == std::string_view::npos ? text.size() : next;
            literal(text.substr(i, end - i));
            i = end;
            continue;
        }
        const std::size_t close = text.find('}', i);
        if (close == std::string_view::npos) {
            return "the '{' at character " + std::to_string(i + 1) + " is never closed; write '{{' for a brace";
        }
        const std::string_view inside = text.substr(i + 1, close - i - 1);
        const std::size_t colon = inside.find(':');
        TemplateSlot s{inside.substr(0, colon), false};
        if (colon != std::string_view::npos) {
            if (inside.substr(colon + 1) != "hex") {
                return "'{" + std::string(inside) + "}': the only style is ':hex'";
            }
            s.hex = true;
        }
        if (s.name.empty() || s.name.find('{') != std::string_view::npos) {
            return "'{" + std::string(inside) + "}' names nothing";
        }
        slot(s);
        i = close + 1;
    }
    return std::nullopt;
}

/// What is wrong with @p text, or with a name in it (@p known(name) false); nullopt
/// when it may be expanded.
template <class Known>
[[nodiscard]] std::optional<std::string> template_error(std::string_view text, Known&& known) {
    std::optional<std::string> unknown;
    auto error = walk_template(
        text, [](std::string_view) {},
        [&](const TemplateSlot& s) {
            if (!unknown && !known(s.name)) unknown = "'{" + std::string(s.name) + "}' is not a name it may use";
        });
    return error ? error : unknown;
}

/// @p text with each placeholder replaced by @p value(slot) (a std::string). A text
/// that template_error() refused expands as far as it is well-formed.
template <class Value>
[[nodiscard]] std::string expand_template(std::string_view text, Value&& value) {
    std::string out;
    (void)walk_template(
        text, [&out](std::string_view piece) { out += piece; },
        [&](const TemplateSlot& s) { out += value(s); });
    return out;
}

/// True when @p text has a placeholder (a '{' not doubled).
[[nodiscard]] inline bool has_placeholder(std::string_view text) {
    bool found = false;
    (void)walk_template(text, [](std::string_view) {}, [&found](const TemplateSlot&) { found = true; });
    return found;
}

}  // namespace fieldbridge::core
