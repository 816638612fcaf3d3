// core::Error: the project's one exception type carries what failed, where, and what
// to do, and what() reads as one line for the journal.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace core = fieldbridge::core;

TEST_CASE("core error: what() is where, what failed, and the hint in parentheses") {
    const core::Error error("cannot open: No such file or directory", "serial port /dev/ttyUSB0",
                            "is the adapter plugged in?");
    CHECK(std::string(error.what()) ==
          "serial port /dev/ttyUSB0: cannot open: No such file or directory (is the adapter plugged in?)");
    CHECK(error.failed() == "cannot open: No such file or directory");
    CHECK(error.where() == "serial port /dev/ttyUSB0");
    CHECK(error.hint() == "is the adapter plugged in?");
}

TEST_CASE("core error: empty parts are left out; a one-string error keeps its message") {
    CHECK(std::string(core::Error("no listen address", "Modbus TCP", "").what()) == "Modbus TCP: no listen address");
    CHECK(std::string(core::Error("no listen address", "", "add one").what()) == "no listen address (add one)");
    const core::Error whole("line timing: baud rate 0 is not a rate; configure the line's baud");
    CHECK(std::string(whole.what()) == "line timing: baud rate 0 is not a rate; configure the line's baud");
    CHECK(whole.where().empty());
    CHECK(whole.hint().empty());
}

TEST_CASE("core error: InvalidArgument is a project error and a std::runtime_error") {
    try {
        throw core::InvalidArgument("metric 1bad: invalid name");
    } catch (const core::Error& e) {
        CHECK(std::string(e.what()) == "metric 1bad: invalid name");
    }
    CHECK_THROWS_AS(throw core::InvalidArgument("x"), std::runtime_error);
    CHECK_THROWS_AS(throw core::InvalidArgument("x"), core::InvalidArgument);
}
