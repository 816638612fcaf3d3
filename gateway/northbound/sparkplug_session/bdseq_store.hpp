#pragma once
/// @file bdseq_store.hpp
/// The edge node's birth/death sequence number (bdSeq), kept across restarts in
/// `<state_dir>/sparkplug-bdseq` (docs/sparkplug-session.md, "bdSeq").
///
/// bdSeq starts at 0 and goes up by one, 255 wrapping to 0, on every new MQTT CONNECT
/// (tck-id-topics-nbirth-bdseq-increment,
/// tck-id-message-flow-edge-node-birth-publish-will-message-payload-bdSeq). next() is
/// called before every connection attempt, failed ones included, and the value is on
/// disk before it is returned: a CONNECT that reached the server may have registered
/// its will whatever the outcome the client saw, so a value once put in a will is
/// never put in another one, even after a crash (eclipse-sparkplug/sparkplug#593).
///
/// The file holds the last value used, as decimal text and a newline; it is written
/// to a temporary file in the same folder, fsync'ed, renamed over the old one, and
/// the folder fsync'ed.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace fieldbridge::northbound::sparkplug_session {

class BdSeqStore {
public:
    /// The name of the file in the state directory.
    static constexpr const char* file_name = "sparkplug-bdseq";

    /// Reads the last value from @p state_dir. A missing, unreadable or corrupt file
    /// starts the sequence at 0; warning() then says which file and why.
    explicit BdSeqStore(std::filesystem::path state_dir);

    /// The bdSeq of the next CONNECT, already persisted. Throws core::Error (the
    /// file, the system's reason, what to do) when it cannot be written: the node
    /// must not connect with a value it may use again.
    [[nodiscard]] std::uint8_t next();

    /// The last value handed out or read; nullopt before the first.
    [[nodiscard]] std::optional<std::uint8_t> last() const noexcept { return last_; }
    /// Why the stored value could not be used at start-up; empty when it could, or
    /// when there was no file yet (a first start).
    [[nodiscard]] const std::string& warning() const noexcept { return warning_; }
    [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

private:
    void write(std::uint8_t value) const;

    std::filesystem::path path_;
    std::optional<std::uint8_t> last_;
    std::string warning_;
};

}  // namespace fieldbridge::northbound::sparkplug_session
