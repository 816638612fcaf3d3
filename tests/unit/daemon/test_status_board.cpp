#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "daemon/status_board.hpp"

using fieldbridge::daemon::count_of;
using fieldbridge::daemon::StatusBoard;

TEST_CASE("the status line joins the non-empty parts in registration order") {
    StatusBoard board;
    CHECK(board.compose().empty());
    board.add([] { return std::string("2 lines"); });
    board.add([] { return std::string(); });
    board.add([] { return std::string("4 devices"); });
    board.add([] { return std::string("0 TCP clients"); });
    CHECK(board.compose() == "2 lines, 4 devices, 0 TCP clients");
}

TEST_CASE("a throwing contributor does not hide the others") {
    StatusBoard board;
    board.add([] { return std::string("2 lines"); });
    board.add([]() -> std::string { throw std::runtime_error("broken"); });
    board.add([] { return std::string("1 client"); });
    CHECK(board.compose() == "2 lines, <status unavailable>, 1 client");
}

TEST_CASE("the status line stays one line and bounded") {
    StatusBoard board;
    board.add([] { return std::string("a\nb\rc"); });
    CHECK(board.compose() == "a b c");

    StatusBoard long_board;
    long_board.add([] { return std::string(500, 'x'); });
    const auto line = long_board.compose();
    CHECK(line.size() == StatusBoard::max_length);
    CHECK(line.substr(line.size() - 3) == "...");
}

TEST_CASE("take_if_changed publishes only changes, unless forced") {
    StatusBoard board;
    int clients = 0;
    board.add([&] { return count_of(static_cast<std::size_t>(clients), "TCP client", "TCP clients"); });
    CHECK(board.take_if_changed() == std::optional<std::string>("0 TCP clients"));
    CHECK_FALSE(board.take_if_changed().has_value());
    CHECK(board.take_if_changed(true) == std::optional<std::string>("0 TCP clients"));
    clients = 1;
    CHECK(board.take_if_changed() == std::optional<std::string>("1 TCP client"));
    CHECK_FALSE(board.take_if_changed().has_value());
}

TEST_CASE("count_of picks singular or plural") {
    CHECK(count_of(0, "line", "lines") == "0 lines");
    CHECK(count_of(1, "line", "lines") == "1 line");
    CHECK(count_of(2, "device", "devices") == "2 devices");
}
