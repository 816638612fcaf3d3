#include "northbound/sparkplug_session/bdseq_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/error.hpp"

namespace fieldbridge::northbound::sparkplug_session {

namespace {

/// The file's content is at most "255\n"; more is not ours.
constexpr std::size_t max_file_bytes = 16;

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what, int error) {
    throw core::Error(what + ": " + std::strerror(error), "Sparkplug bdSeq file " + path.string(),
                      "check that the state directory (sparkplug.state_dir) exists and that the service "
                      "user may write to it");
}

/// Closes the descriptor on every path.
class Descriptor {
public:
    explicit Descriptor(int fd) : fd_(fd) {}
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    ~Descriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    [[nodiscard]] int get() const noexcept { return fd_; }
    /// Closes now, reporting a failure (a write error may only show at close).
    [[nodiscard]] int close() noexcept {
        const int result = ::close(fd_);
        fd_ = -1;
        return result;
    }

private:
    int fd_;
};

}  // namespace

BdSeqStore::BdSeqStore(std::filesystem::path state_dir) : path_(std::move(state_dir) / file_name) {
    std::ifstream in(path_, std::ios::binary);
    if (!in) {
        std::error_code ec;
        if (std::filesystem::exists(path_, ec)) {
            warning_ = "cannot read the Sparkplug bdSeq file " + path_.string() + ": bdSeq starts again at 0";
        }
        return;
    }
    std::string text(max_file_bytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    std::string_view digits = text;
    if (!digits.empty() && digits.back() == '\n') digits.remove_suffix(1);
    unsigned value = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (digits.empty() || error != std::errc{} || end != digits.data() + digits.size() || value > 255) {
        warning_ = "the Sparkplug bdSeq file " + path_.string() +
                   " does not hold a number 0..255: bdSeq starts again at 0 (the file is rewritten at the "
                   "next connection)";
        return;
    }
    last_ = static_cast<std::uint8_t>(value);
}

std::uint8_t BdSeqStore::next() {
    const std::uint8_t value = last_ ? static_cast<std::uint8_t>(*last_ + 1) : std::uint8_t{0};
    write(value);
    last_ = value;
    return value;
}

void BdSeqStore::write(std::uint8_t value) const {
    const std::filesystem::path temporary = path_.string() + ".tmp";
    const std::string text = std::to_string(value) + "\n";
    {
        Descriptor file(::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
        if (file.get() < 0) fail(temporary, "cannot create the temporary file", errno);
        if (::write(file.get(), text.data(), text.size()) != static_cast<ssize_t>(text.size())) {
            fail(temporary, "cannot write", errno);
        }
        if (::fsync(file.get()) != 0) fail(temporary, "cannot flush to disk", errno);
        if (file.close() != 0) fail(temporary, "cannot close", errno);
    }
    if (::rename(temporary.c_str(), path_.c_str()) != 0) fail(path_, "cannot replace the file", errno);
    const std::filesystem::path folder = path_.parent_path().empty() ? "." : path_.parent_path();
    Descriptor directory(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (directory.get() < 0 || ::fsync(directory.get()) != 0) fail(folder, "cannot flush the folder to disk", errno);
}

}  // namespace fieldbridge::northbound::sparkplug_session
