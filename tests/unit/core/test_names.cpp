// core/: each shared enum has one name table; to_string and parse are its two
// directions, and every value has a name.
#include <doctest/doctest.h>

#include <string>

#include "core/device_type.hpp"
#include "core/log_level.hpp"
#include "core/parity.hpp"
#include "core/register_table.hpp"
#include "core/word_order.hpp"

namespace core = fieldbridge::core;

namespace {

template <class E, std::size_t N>
void check_round_trip(const core::NameTable<E, N>& names) {
    CHECK(&core::Names<E>::table == &names);  // the table the functions use
    for (const auto& [name, value] : names) {
        CAPTURE(std::string(name));
        CHECK(core::to_string(value) == name);
        CHECK(core::parse<E>(name) == value);
    }
    CHECK_FALSE(core::parse<E>("").has_value());
    CHECK_FALSE(core::parse<E>("nonsense").has_value());
}

}  // namespace

TEST_CASE("core names: every shared enum reads back what it writes") {
    check_round_trip(core::device_type_names);
    check_round_trip(core::word_order_names);
    check_round_trip(core::register_table_names);
    check_round_trip(core::parity_names);
    check_round_trip(core::log_level_names);
}

TEST_CASE("core names: the config file's spellings") {
    CHECK(core::to_string(core::DeviceType::hiwin_xeg) == "hiwin-xeg");
    CHECK(core::to_string(core::DeviceType::wtec_ascii) == "wtec-ascii");
    CHECK_FALSE(core::parse<core::DeviceType>("hiwin_xeg").has_value());  // the dash, not the C++ name
    CHECK(core::to_string(core::RegisterTable::discrete_inputs) == "discrete_inputs");
    CHECK(core::to_string(core::WordOrder::low_first) == "low_first");
    CHECK(core::to_string(core::LogLevel::warning) == "warning");
    CHECK_FALSE(core::parse<core::LogLevel>("warn").has_value());
    CHECK(core::to_string(static_cast<core::Parity>(7)) == "unknown");
}

TEST_CASE("core names: log levels are ordered by severity; register tables index the image") {
    CHECK(core::LogLevel::trace < core::LogLevel::debug);
    CHECK(core::LogLevel::debug < core::LogLevel::info);
    CHECK(core::LogLevel::info < core::LogLevel::warning);
    CHECK(core::LogLevel::warning < core::LogLevel::error);
    CHECK(static_cast<std::size_t>(core::RegisterTable::input) == core::table_count - 1);
    CHECK(core::is_bit_table(core::RegisterTable::coils));
    CHECK(core::is_bit_table(core::RegisterTable::discrete_inputs));
    CHECK_FALSE(core::is_bit_table(core::RegisterTable::holding));
    CHECK_FALSE(core::is_bit_table(core::RegisterTable::input));
}

TEST_CASE("core names: parity letters for libmodbus and 8N1") {
    CHECK(core::parity_letter(core::Parity::none) == 'N');
    CHECK(core::parity_letter(core::Parity::even) == 'E');
    CHECK(core::parity_letter(core::Parity::odd) == 'O');
    CHECK(core::parse_parity_letter('E') == core::Parity::even);
    CHECK(core::parse_parity_letter('o') == core::Parity::odd);
    CHECK(core::parse_parity_letter('n') == core::Parity::none);
    CHECK_FALSE(core::parse_parity_letter('X').has_value());
    CHECK_FALSE(core::parse_parity_letter('e' - 'a' + 'A' + 1).has_value());
}
