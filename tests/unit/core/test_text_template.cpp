// The text templates of points (core/text_template.hpp): placeholders, braces, errors.
#include <doctest/doctest.h>

#include <string>
#include <string_view>

#include "core/text_template.hpp"

namespace {

namespace fc = fieldbridge::core;

[[nodiscard]] std::string expanded(std::string_view text) {
    return fc::expand_template(text, [](const fc::TemplateSlot& slot) {
        return "<" + std::string(slot.name) + (slot.hex ? ":hex" : "") + ">";
    });
}

[[nodiscard]] std::string error_of(std::string_view text) {
    const auto error = fc::template_error(text, [](std::string_view name) { return name == "0" || name == "value"; });
    return error ? *error : std::string{};
}

}  // namespace

TEST_CASE("text template: placeholders are replaced, doubled braces are braces") {
    CHECK(expanded("V{0}.{1}") == "V<0>.<1>");
    CHECK(expanded("{value:hex}") == "<value:hex>");
    CHECK(expanded("{{0}} is {0}") == "{0} is <0>");
    CHECK(expanded("plain") == "plain");
    CHECK(expanded("") == "");
    CHECK(fc::has_placeholder("a {0}"));
    CHECK_FALSE(fc::has_placeholder("a {{0}}"));
    CHECK_FALSE(fc::has_placeholder(""));
}

TEST_CASE("text template: what is wrong is said, with where") {
    CHECK(error_of("V{0}").empty());
    CHECK(error_of("unknown ({value:hex})").empty());
    CHECK(error_of("a { b") == "the '{' at character 3 is never closed; write '{{' for a brace");
    CHECK(error_of("a } b") == "a '}' at character 3 closes nothing; write '}}' for a brace");
    CHECK(error_of("{}") == "'{}' names nothing");
    CHECK(error_of("{0:x}") == "'{0:x}': the only style is ':hex'");
    CHECK(error_of("{1}") == "'{1}' is not a name it may use");
    CHECK(error_of("{a{0}") == "'{a{0}' names nothing");
    // A malformed text expands as far as it is well-formed, never past its end.
    CHECK(expanded("x{0}y{") == "x<0>y");
}
