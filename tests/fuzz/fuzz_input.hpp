#pragma once
/// @file fuzz_input.hpp
/// What every harness needs of its input: a few leading bytes that choose the
/// context (a request, an address, a command set), the rest as the bytes under test,
/// and chunk boundaries derived from the input, so that a framer sees the stream
/// arrive the way a socket or a serial port delivers it (docs/fuzzing.md).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

namespace fieldbridge::fuzz {

/// Prints which invariant broke, where, and aborts: libFuzzer reports a crash and
/// saves the input. (A bare __builtin_trap() loses the line: the optimiser merges the
/// traps of one function.)
[[noreturn]] inline void invariant_failed(const char* condition, const char* file, int line) {
    std::fprintf(stderr, "%s:%d: invariant of the code under test broken: %s\n", file, line, condition);
    std::abort();
}

}  // namespace fieldbridge::fuzz

/// Checks an invariant of the code under test; a violation is a crash that names it.
#define FB_FUZZ_CHECK(condition) \
    ((condition) ? void(0) : ::fieldbridge::fuzz::invariant_failed(#condition, __FILE__, __LINE__))

namespace fieldbridge::fuzz {

/// Reads an input from the front; past the end every read is 0 / empty.
class FuzzInput {
public:
    FuzzInput(const std::uint8_t* data, std::size_t size) : bytes_(data, size) {}

    [[nodiscard]] std::uint8_t byte() {
        if (bytes_.empty()) return 0;
        const std::uint8_t b = bytes_.front();
        bytes_ = bytes_.subspan(1);
        return b;
    }

    /// Up to @p count bytes (fewer at the end of the input).
    [[nodiscard]] std::span<const std::uint8_t> take(std::size_t count) {
        const std::size_t n = count < bytes_.size() ? count : bytes_.size();
        const auto taken = bytes_.first(n);
        bytes_ = bytes_.subspan(n);
        return taken;
    }

    /// Everything not read yet.
    [[nodiscard]] std::span<const std::uint8_t> rest() {
        const auto all = bytes_;
        bytes_ = {};
        return all;
    }

private:
    std::span<const std::uint8_t> bytes_;
};

/// Splits @p stream into chunks as a reader would receive them: @p seed's bits choose
/// the chunk sizes (1 to 16 bytes, or everything left), so one input byte gives the
/// fuzzer control over where the stream is cut. Every chunk is non-empty; together
/// they are @p stream.
[[nodiscard]] inline std::vector<std::span<const std::uint8_t>> chunks(std::span<const std::uint8_t> stream,
                                                                       std::uint8_t seed) {
    std::vector<std::span<const std::uint8_t>> out;
    std::uint32_t state = seed * 2654435761u + 1u;
    while (!stream.empty()) {
        state = state * 1103515245u + 12345u;
        const std::uint32_t pick = (state >> 16) & 0x1F;
        const std::size_t want = pick >= 16 ? stream.size() : pick + 1;
        const std::size_t n = want < stream.size() ? want : stream.size();
        out.push_back(stream.first(n));
        stream = stream.subspan(n);
    }
    return out;
}

}  // namespace fieldbridge::fuzz
