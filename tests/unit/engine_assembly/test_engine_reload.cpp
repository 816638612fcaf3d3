// Engine::apply (a SIGHUP reload): unchanged lines keep their worker, port and queue;
// a device whose freshness or command timing changed keeps its agent; a device whose
// profile settings changed is swapped on a port that stays open; a line whose serial
// settings changed restarts (its port is opened again). The ports are socket pairs
// that count their opens: nothing here needs a pty or a device.
#include <doctest/doctest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <asio/io_context.hpp>

#include "config/config_loader.hpp"
#include "engine/engine.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fc = fieldbridge::config;
using namespace std::chrono_literals;

/// Opens per port path, shared by every port the factory made.
using OpenCounts = std::map<std::string, int>;

class CountingPort final : public fe::SerialPort {
public:
    CountingPort(fe::SerialSettings settings, OpenCounts& opens) : settings_(std::move(settings)), opens_(opens) {}
    ~CountingPort() override { close(); }

    void open() override {
        int fds[2] = {-1, -1};
        REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK, 0, fds) == 0);
        fd_ = fds[0];
        peer_ = fds[1];
        ++opens_[settings_.path];
    }
    void close() noexcept override {
        for (int* fd : {&fd_, &peer_}) {
            if (*fd >= 0) ::close(*fd);
            *fd = -1;
        }
    }
    [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }
    [[nodiscard]] int native_handle() const noexcept override { return fd_; }
    [[nodiscard]] std::size_t write_some(fieldbridge::protocol::ByteView bytes) override { return bytes.size(); }
    [[nodiscard]] std::size_t read_some(std::span<std::uint8_t> /*buffer*/) override { return 0; }
    void discard_input() noexcept override {}
    [[nodiscard]] const fe::SerialSettings& settings() const noexcept override { return settings_; }

private:
    fe::SerialSettings settings_;
    OpenCounts& opens_;
    int fd_ = -1;
    int peer_ = -1;
};

constexpr const char* base_config = R"(gateway: {id: t}
modbus_tcp: {listen: ["127.0.0.1:15999"]}
lines:
  - name: line-a
    port: /dev/fb-test-a
    devices:
      - {name: gripper, type: hiwin-xeg, address: 1, unit_id: 1, max_age: 200ms}
      - {name: stepper, type: excd203mb, address: 2, unit_id: 2}
  - name: line-b
    port: /dev/fb-test-b
    devices:
      - {name: wtec, type: wtec-rtu, address: 1, unit_id: 3}
)";

[[nodiscard]] std::shared_ptr<const fc::Config> config_of(const std::string& yaml) {
    return fc::load_config_string(yaml, "reload-test.yaml");
}

[[nodiscard]] std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}

struct Cell {
    asio::io_context io;
    OpenCounts opens;
    fe::Engine engine{io, *config_of(base_config), fe::LogSink{},
                      [this](const fe::SerialSettings& settings) -> std::unique_ptr<fe::SerialPort> {
                          return std::make_unique<CountingPort>(settings, opens);
                      }};
    Cell() {
        engine.start();
        io.run_for(20ms);
    }
    ~Cell() { engine.stop(); }

    [[nodiscard]] const fe::LineEntry& line(const std::string& name) const {
        for (const auto& entry : engine.lines()) {
            if (entry.config.name == name) return entry;
        }
        FAIL("no line " << name);
        throw std::logic_error("unreachable");
    }
};

TEST_CASE("an identical configuration changes nothing") {
    Cell cell;
    const auto* worker_a = cell.line("line-a").worker.get();
    const auto* gripper = cell.engine.find_device("gripper");
    const auto report = cell.engine.apply(*config_of(base_config));
    CHECK_FALSE(report.changed());
    CHECK(report.lines_kept.size() == 2);
    CHECK(cell.line("line-a").worker.get() == worker_a);
    CHECK(cell.engine.find_device("gripper") == gripper);
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
    CHECK(cell.opens["/dev/fb-test-b"] == 1);
}

TEST_CASE("a change on one line leaves the other line's worker, port and queue alone") {
    Cell cell;
    const auto* worker_a = cell.line("line-a").worker.get();
    const auto revision_a = cell.line("line-a").revision;
    const auto* wtec = cell.engine.find_device("wtec");
    // Line b's baud changes: it restarts; line a is untouched.
    const auto next = replaced(base_config, "port: /dev/fb-test-b\n", "port: /dev/fb-test-b\n    baud: 57600\n");
    const auto report = cell.engine.apply(*config_of(next));
    cell.io.run_for(20ms);
    CHECK(report.lines_kept == std::vector<std::string>{"line-a"});
    CHECK(report.lines_restarted == std::vector<std::string>{"line-b"});
    CHECK(cell.line("line-a").worker.get() == worker_a);
    CHECK(cell.line("line-a").revision == revision_a);
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
    CHECK(cell.opens["/dev/fb-test-b"] == 2);
    CHECK(cell.engine.find_device("wtec") != nullptr);
    CHECK(cell.engine.find_device("wtec") != wtec);
    CHECK(cell.line("line-b").worker->line_up());
    CHECK(cell.engine.find_unit(fieldbridge::core::UnitId{3}) == cell.engine.find_device("wtec"));
}

TEST_CASE("a device's max_age and command_ttl change in place: same agent, same port") {
    Cell cell;
    auto* gripper = cell.engine.find_device("gripper");
    const auto index = gripper->config().index;
    const auto next = replaced(base_config, "max_age: 200ms}", "max_age: 1s, command_ttl: 2s}");
    const auto report = cell.engine.apply(*config_of(next));
    CHECK(report.devices_retuned == std::vector<std::string>{"gripper"});
    CHECK(report.lines_updated == std::vector<std::string>{"line-a"});
    CHECK(report.lines_restarted.empty());
    CHECK(cell.engine.find_device("gripper") == gripper);
    CHECK(gripper->config().index == index);
    CHECK(gripper->config().max_age == 1s);
    CHECK(gripper->config().command_ttl == 2s);
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
}

TEST_CASE("a device whose profile settings changed is swapped on the open port") {
    Cell cell;
    const auto* worker_a = cell.line("line-a").worker.get();
    auto* stepper = cell.engine.find_device("stepper");
    const auto* gripper = cell.engine.find_device("gripper");
    const auto next = replaced(base_config, "{name: stepper, type: excd203mb, address: 2, unit_id: 2}",
                               "{name: stepper, type: excd203mb, address: 2, unit_id: 2, allow_protected: true}");
    const auto report = cell.engine.apply(*config_of(next));
    cell.io.run_for(20ms);
    CHECK(report.devices_replaced == std::vector<std::string>{"stepper"});
    CHECK(cell.line("line-a").worker.get() == worker_a);
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
    auto* swapped = cell.engine.find_device("stepper");
    REQUIRE(swapped != nullptr);
    CHECK(swapped != stepper);
    CHECK(swapped->config().index != stepper->config().index);  // a new scheduler entry
    CHECK(worker_a->scheduler().has_device(swapped->config().index));
    CHECK(worker_a->scheduler().has_device(stepper->config().index));  // the old one drains
    CHECK(cell.engine.find_device("gripper") == gripper);
    CHECK(cell.engine.find_unit(fieldbridge::core::UnitId{2}) == swapped);
    CHECK(cell.line("line-a").retired.size() == 1);

    // The old agent's polls left the queue with it (nobody waits for them), so the
    // next reload that touches the line lets the drained agent go.
    CHECK(worker_a->scheduler().queued(stepper->config().index) == 0);
    const auto old_index = stepper->config().index;
    const auto third = replaced(next, "max_age: 200ms}", "max_age: 300ms}");
    (void)cell.engine.apply(*config_of(third));
    CHECK(cell.line("line-a").retired.empty());
    CHECK_FALSE(worker_a->scheduler().has_device(old_index));
}

TEST_CASE("a swapped device's queued request still goes out and is answered, whatever reloads follow") {
    Cell cell;
    auto* worker_a = cell.line("line-a").worker.get();
    auto* stepper = cell.engine.find_device("stepper");
    // A client's read of the stepper, queued behind the line's polls (the port never
    // answers: each transaction waits its response timeout).
    std::optional<fieldbridge::protocol::Response> answer;
    stepper->request(fieldbridge::protocol::ReadRegistersRequest{0x03, 0x0014, 2},
                     [&answer](const fieldbridge::protocol::Response& response) { answer = response; });
    const auto old_index = stepper->config().index;
    const auto next = replaced(base_config, "{name: stepper, type: excd203mb, address: 2, unit_id: 2}",
                               "{name: stepper, type: excd203mb, address: 2, unit_id: 2, allow_protected: true}");
    (void)cell.engine.apply(*config_of(next));
    // A storm: the reloads right after it keep the old agent while its request is open.
    const auto third = replaced(next, "max_age: 200ms}", "max_age: 300ms}");
    (void)cell.engine.apply(*config_of(third));
    (void)cell.engine.apply(*config_of(next));
    CHECK_FALSE(answer.has_value());
    CHECK(cell.line("line-a").retired.size() == 1);
    CHECK(worker_a->scheduler().has_device(old_index));
    // It went to the line and was answered by what the line saw: no reply, 0x0B; never
    // cancelled (0x0A) by a reload.
    const auto until = std::chrono::steady_clock::now() + 5s;
    while (!answer && std::chrono::steady_clock::now() < until) cell.io.run_for(10ms);
    REQUIRE(answer.has_value());
    const auto* refused = std::get_if<fieldbridge::protocol::ExceptionResponse>(&*answer);
    REQUIRE(refused != nullptr);
    CHECK(refused->code == fieldbridge::protocol::ExceptionCode::gateway_target_failed);
    (void)cell.engine.apply(*config_of(third));
    CHECK(cell.line("line-a").retired.empty());
    CHECK_FALSE(worker_a->scheduler().has_device(old_index));
}

TEST_CASE("devices added and removed on a running line; lines added and removed") {
    Cell cell;
    const auto* worker_a = cell.line("line-a").worker.get();
    std::string next = replaced(base_config, "      - {name: stepper, type: excd203mb, address: 2, unit_id: 2}\n",
                                "      - {name: gripper-2, type: hiwin-xeg, address: 4, unit_id: 4}\n");
    next = next.substr(0, next.find("  - name: line-b")) +
           "  - name: line-c\n    port: /dev/fb-test-c\n    devices:\n"
           "      - {name: wtec-c, type: wtec-rtu, address: 1, unit_id: 5}\n";
    const auto report = cell.engine.apply(*config_of(next));
    cell.io.run_for(20ms);
    CHECK(report.devices_added == std::vector<std::string>{"gripper-2"});
    CHECK(report.devices_removed == std::vector<std::string>{"stepper"});
    CHECK(report.lines_added == std::vector<std::string>{"line-c"});
    CHECK(report.lines_removed == std::vector<std::string>{"line-b"});
    CHECK(cell.line("line-a").worker.get() == worker_a);
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
    CHECK(cell.opens["/dev/fb-test-c"] == 1);
    CHECK(cell.engine.find_device("stepper") == nullptr);
    CHECK(cell.engine.find_unit(fieldbridge::core::UnitId{4}) == cell.engine.find_device("gripper-2"));
    CHECK(cell.engine.find_unit(fieldbridge::core::UnitId{3}) == nullptr);
    CHECK(cell.engine.devices().size() == 3);
    CHECK(cell.line("line-c").worker->line_up());
}

TEST_CASE("line policies (retries, offline threshold, broadcast unit) change without a restart") {
    Cell cell;
    const auto* worker_a = cell.line("line-a").worker.get();
    const auto revision = cell.line("line-a").revision;
    const auto next = replaced(base_config, "port: /dev/fb-test-a\n",
                               "port: /dev/fb-test-a\n    read_retries: 3\n    offline_after: 5\n"
                               "    broadcast_unit: 100\n");
    const auto report = cell.engine.apply(*config_of(next));
    CHECK(report.lines_updated == std::vector<std::string>{"line-a"});
    CHECK(cell.line("line-a").worker.get() == worker_a);
    CHECK(cell.line("line-a").revision != revision);
    CHECK(cell.line("line-a").broadcast_unit == fieldbridge::core::UnitId{100});
    CHECK(cell.opens["/dev/fb-test-a"] == 1);
}

TEST_CASE("the reload report reads as one log line") {
    fe::ReloadReport report;
    CHECK(report.summary() == "no lines");
    report.lines_kept = {"a", "b"};
    report.devices_retuned = {"x"};
    CHECK(report.summary() == "lines kept: a, b; devices retuned: x");
}

}  // namespace
