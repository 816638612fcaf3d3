// The bdSeq file: start at 0, +1 per connection attempt, wrap, survive a restart,
// and start again at 0 with a warning on a corrupt file.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "northbound/sparkplug_session/bdseq_store.hpp"
#include "temp_dir.hpp"

namespace {

namespace ss = fieldbridge::northbound::sparkplug_session;

std::string read(const std::filesystem::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void write(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

TEST_CASE("bdSeq starts at 0 and is on disk before it is used (tck-id-topics-nbirth-bdseq-increment)") {
    fieldbridge::test::TempDir dir;
    ss::BdSeqStore store(dir.path());
    CHECK(store.warning().empty());  // a first start is not a problem
    CHECK_FALSE(store.last());
    CHECK(store.next() == 0);
    CHECK(read(dir.path() / "sparkplug-bdseq") == "0\n");
    CHECK(store.next() == 1);
    CHECK(read(dir.path() / "sparkplug-bdseq") == "1\n");
    CHECK_FALSE(std::filesystem::exists(dir.path() / "sparkplug-bdseq.tmp"));
}

TEST_CASE("bdSeq survives a restart and wraps 255 -> 0") {
    fieldbridge::test::TempDir dir;
    {
        ss::BdSeqStore store(dir.path());
        for (int i = 0; i < 255; ++i) static_cast<void>(store.next());
        CHECK(store.last() == 254);
    }
    ss::BdSeqStore again(dir.path());
    CHECK(again.warning().empty());
    CHECK(again.last() == 254);
    CHECK(again.next() == 255);
    CHECK(again.next() == 0);
    CHECK(again.next() == 1);
}

TEST_CASE("a corrupt bdSeq file starts at 0 with a warning that names the file") {
    fieldbridge::test::TempDir dir;
    const auto path = dir.path() / "sparkplug-bdseq";
    for (const char* bad : {"", "abc\n", "256\n", "-1\n", "12 \n", "1\n2\n", "99999999999999999999\n"}) {
        CAPTURE(bad);
        write(path, bad);
        ss::BdSeqStore store(dir.path());
        CHECK(store.warning().find(path.string()) != std::string::npos);
        CHECK(store.next() == 0);
        CHECK(read(path) == "0\n");
    }
    write(path, "17");  // no newline: still a number
    ss::BdSeqStore store(dir.path());
    CHECK(store.warning().empty());
    CHECK(store.next() == 18);
}

TEST_CASE("a state directory that cannot be written makes next() throw, naming the file and what to do") {
    fieldbridge::test::TempDir dir;
    const auto missing = dir.path() / "no-such-dir";
    ss::BdSeqStore store(missing);
    try {
        static_cast<void>(store.next());
        FAIL("next() did not throw");
    } catch (const fieldbridge::core::Error& error) {
        const std::string text = error.what();
        CHECK(text.find("sparkplug-bdseq") != std::string::npos);
        CHECK(text.find("sparkplug.state_dir") != std::string::npos);
    }
    CHECK_FALSE(store.last());  // nothing handed out
}
