// A main for a libFuzzer harness in the gcc sanitizer build (docs/fuzzing.md, "In the
// test build"): runs LLVMFuzzerTestOneInput on every file of the given directories
// (the seed corpora of make_fuzz_seeds, and any inputs a fuzzing campaign kept), then
// on a fixed number of mutants of each, made by a seeded generator so that a run is
// the same every time. Not a fuzzer: it has no coverage feedback. What it adds to
// the unit tests is the harnesses' invariants, checked under ASan/UBSan on the
// manuals' frames and their near misses in every `deploy/run-tests`; the coverage-
// guided search is tests/fuzz/run-fuzzers (clang, libFuzzer).
// Usage: <harness> [--mutants N] DIR...   Exit 0, or the harness aborts on a broken
// invariant after printing it, or a sanitizer stops it; either way the input is
// written to fuzz-replay-failing-input (the working directory) as it dies, for
// `run-fuzzers`' harness to reproduce.

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;
using Input = std::vector<std::uint8_t>;

Input read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return Input(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The input being run, for the crash handlers below. A signal handler and the
/// sanitizers' death callback take no argument, so this is the one file-scope
/// variable of the program (libFuzzer keeps its current input the same way).
struct CurrentInput {
    const std::uint8_t* data = nullptr;
    std::size_t size = 0;
};
CurrentInput current;

/// Writes the input being run to fuzz-replay-failing-input; async-signal-safe (open,
/// write, close), so it can run in a SIGABRT handler.
void save_current_input() {
    const int fd = ::open("fuzz-replay-failing-input", O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return;
    if (::write(fd, current.data, current.size) < 0) {
        // Nothing more can be done while dying.
    }
    ::close(fd);
}

/// A broken FB_FUZZ_CHECK aborts; the input is saved, then abort() goes on.
extern "C" void save_on_abort(int /*signal*/) { save_current_input(); }

void run(const Input& input) {
    current = CurrentInput{input.data(), input.size()};
    LLVMFuzzerTestOneInput(input.data(), input.size());
}

/// One to four of libFuzzer's simplest mutations: flip a bit, set a byte to an
/// interesting value, insert or erase a byte, cut the tail, duplicate a span.
Input mutate(Input input, std::mt19937& random) {
    static constexpr std::uint8_t interesting[] = {0x00, 0x01, 0x7F, 0x80, 0xFE, 0xFF, '\r', '\n', '$', ':'};
    const auto pick = [&random](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(random); };
    const std::size_t rounds = 1 + pick(4);
    for (std::size_t r = 0; r < rounds; ++r) {
        switch (pick(6)) {
            case 0:
                if (!input.empty()) input[pick(input.size())] ^= static_cast<std::uint8_t>(1u << pick(8));
                break;
            case 1:
                if (!input.empty()) input[pick(input.size())] = interesting[pick(std::size(interesting))];
                break;
            case 2:
                input.insert(input.begin() + static_cast<std::ptrdiff_t>(pick(input.size() + 1)),
                             static_cast<std::uint8_t>(pick(256)));
                break;
            case 3:
                if (!input.empty()) input.erase(input.begin() + static_cast<std::ptrdiff_t>(pick(input.size())));
                break;
            case 4:
                if (!input.empty()) input.resize(pick(input.size()));
                break;
            default:
                if (!input.empty() && input.size() < 4096) {
                    const std::size_t from = pick(input.size());
                    const std::size_t length = 1 + pick(std::min<std::size_t>(input.size() - from, 64));
                    const Input span(input.begin() + static_cast<std::ptrdiff_t>(from),
                                     input.begin() + static_cast<std::ptrdiff_t>(from + length));
                    input.insert(input.begin() + static_cast<std::ptrdiff_t>(pick(input.size() + 1)), span.begin(),
                                 span.end());
                }
                break;
        }
    }
    return input;
}

}  // namespace

int main(int argc, char** argv) {
    std::size_t mutants = 200;
    std::vector<fs::path> dirs;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--mutants" && i + 1 < argc) {
            mutants = std::stoul(argv[++i]);
        } else {
            dirs.emplace_back(arg);
        }
    }
    std::vector<fs::path> files;
    for (const auto& dir : dirs) {
        if (!fs::is_directory(dir)) {
            std::cerr << argv[0] << ": " << dir.string() << " is not a directory of inputs\n";
            return 2;
        }
        for (const auto& entry : fs::directory_iterator(dir)) {
            if (entry.is_regular_file()) files.push_back(entry.path());
        }
    }
    if (files.empty()) {
        std::cerr << argv[0] << ": no inputs in the given directories; run make_fuzz_seeds first\n";
        return 2;
    }
    std::signal(SIGABRT, save_on_abort);
#if defined(__SANITIZE_ADDRESS__)
    __sanitizer_set_death_callback(save_current_input);  // an ASan or UBSan report
#endif
    std::sort(files.begin(), files.end());  // the same order, so the same mutants, every run
    std::mt19937 random(20261125);
    std::size_t runs = 0;
    run(Input{});
    ++runs;
    for (const auto& file : files) {
        const Input seed = read_file(file);
        run(seed);
        ++runs;
        for (std::size_t m = 0; m < mutants; ++m, ++runs) run(mutate(seed, random));
    }
    fs::remove("fuzz-replay-failing-input");  // from an earlier failing run
    std::cout << argv[0] << ": " << files.size() << " inputs and " << runs - 1 - files.size()
              << " mutants, every invariant held\n";
    return 0;
}
