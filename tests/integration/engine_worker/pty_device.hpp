#pragma once
// The line worker over a real pseudo-terminal: a scripted Modbus-RTU device on the
// master side of a pty (the worker opens the slave through a symlink, as it would
// open /dev/ttyUSB0), and a worker on it with short timeouts (Bench).
#include <doctest/doctest.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <vector>

#include "engine/line_worker.hpp"
#include "engine/posix_serial_port.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/rtu_frame.hpp"
#include "temp_dir.hpp"
#include "worker_test_support.hpp"

namespace worker_test {

using fieldbridge::test::TempDir;

/// What the device does with each request.
struct DeviceScript {
    bool echo = false;                      ///< write the request back first (2-wire adapter)
    Bytes prefix;                           ///< garbage written before each reply
    std::set<std::uint8_t> silent;          ///< function codes it never answers
    unsigned silent_count = 0;              ///< requests to ignore before answering again
};

/// A Modbus-RTU slave on the master side of a pty. The worker opens the slave side
/// through `link()`; unplug() closes the master (the slave then reads EIO, as when a
/// USB adapter goes away) and plug() makes a new pty and re-points the link.
class PtyDevice {
public:
    PtyDevice(asio::io_context& io, std::filesystem::path link) : io_(io), link_(std::move(link)) { plug(); }
    ~PtyDevice() { unplug(); }
    PtyDevice(const PtyDevice&) = delete;
    PtyDevice& operator=(const PtyDevice&) = delete;

    [[nodiscard]] const std::filesystem::path& link() const { return link_; }
    [[nodiscard]] bool plugged() const { return master_ != nullptr; }

    void plug() {
        REQUIRE_FALSE(plugged());
        termios raw{};
        ::cfmakeraw(&raw);
        ::cfsetspeed(&raw, B115200);
        int master_fd = -1;
        int slave_fd = -1;
        std::array<char, 128> name{};
        REQUIRE(::openpty(&master_fd, &slave_fd, name.data(), &raw, nullptr) == 0);
        slave_fd_ = slave_fd;  // held open so the master never reads EIO between opens
        master_ = std::make_unique<asio::posix::stream_descriptor>(io_, master_fd);
        master_->non_blocking(true);
        std::error_code ignored;
        std::filesystem::remove(link_, ignored);
        std::filesystem::create_symlink(name.data(), link_);
        rx_.clear();
        arm();
    }

    void unplug() {
        if (!plugged()) return;
        master_->close();
        master_.reset();
        ::close(slave_fd_);
        slave_fd_ = -1;
        // Like /dev/ttyUSB0 when the adapter goes: the path is gone (and cannot lead
        // to another program's pty that reuses the number).
        std::error_code ignored;
        std::filesystem::remove(link_, ignored);
    }

    DeviceScript script;
    /// Called with each request frame before the device answers.
    std::function<void(const fp::RtuFrame&)> on_request;

    [[nodiscard]] const std::vector<fp::RtuFrame>& requests() const { return requests_; }
    [[nodiscard]] std::size_t bytes_received() const { return bytes_received_; }
    [[nodiscard]] std::size_t count(std::uint8_t function) const {
        std::size_t n = 0;
        for (const auto& frame : requests_) n += (!frame.pdu.empty() && frame.pdu[0] == function) ? 1 : 0;
        return n;
    }
    [[nodiscard]] std::vector<std::uint8_t> functions() const {
        std::vector<std::uint8_t> out;
        for (const auto& frame : requests_) out.push_back(frame.pdu.empty() ? 0 : frame.pdu[0]);
        return out;
    }
    /// Bytes the device could not frame as requests (stray bytes on the wire).
    [[nodiscard]] std::size_t unframed_bytes() const { return unframed_; }

    /// Writes raw bytes towards the worker.
    void send(const Bytes& bytes) {
        REQUIRE(plugged());
        std::size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(master_->native_handle(), bytes.data() + done, bytes.size() - done);
            REQUIRE(n > 0);
            done += static_cast<std::size_t>(n);
        }
    }

    /// The device's register value at @p reg (what FC03/FC04 replies carry).
    [[nodiscard]] static std::uint16_t value_at(std::uint16_t reg) {
        return static_cast<std::uint16_t>(0x1000 + reg);
    }

private:
    void arm() {
        master_->async_wait(asio::posix::descriptor_base::wait_read, [this, alive = std::weak_ptr<char>(alive_)](
                                                                         const asio::error_code& error) {
            if (alive.expired() || error || !plugged()) return;
            std::array<std::uint8_t, 512> buffer{};
            const ssize_t n = ::read(master_->native_handle(), buffer.data(), buffer.size());
            if (n > 0) {
                bytes_received_ += static_cast<std::size_t>(n);
                rx_.insert(rx_.end(), buffer.begin(), buffer.begin() + n);
                frame();
            }
            if (plugged()) arm();
        });
    }

    void frame() {
        while (!rx_.empty()) {
            const auto framed = fp::frame_rtu_request(rx_);
            if (framed.need_more()) return;
            const std::size_t used = std::min(framed.consumed, rx_.size());
            if (framed.malformed()) {
                unframed_ += used;
            } else {
                const Bytes raw(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(used));
                requests_.push_back(framed.value);
                if (on_request) on_request(framed.value);
                answer(framed.value, raw);
            }
            rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(used));
        }
    }

    void answer(const fp::RtuFrame& frame, const Bytes& raw) {
        if (!plugged()) return;  // on_request may unplug
        Bytes out;
        if (script.echo) out = raw;
        const std::uint8_t function = frame.pdu.empty() ? 0 : frame.pdu[0];
        const bool silent = script.silent.count(function) > 0 || script.silent_count > 0;
        if (script.silent_count > 0) --script.silent_count;
        if (!silent && frame.address != 0) {
            out.insert(out.end(), script.prefix.begin(), script.prefix.end());
            const Bytes reply = fp::encode_rtu(frame.address, reply_pdu(frame));
            out.insert(out.end(), reply.begin(), reply.end());
        }
        if (!out.empty()) send(out);
    }

    static Bytes reply_pdu(const fp::RtuFrame& frame) {
        const auto decoded = fp::decode_request(frame.pdu);
        REQUIRE(decoded.complete());
        if (const auto* read = std::get_if<fp::ReadRegistersRequest>(&decoded.value)) {
            std::vector<std::uint16_t> values;
            for (std::uint16_t i = 0; i < read->count; ++i) {
                values.push_back(value_at(static_cast<std::uint16_t>(read->address + i)));
            }
            return fp::encode_response(fp::ReadRegistersResponse{read->function, values});
        }
        if (const auto* single = std::get_if<fp::WriteSingleRegisterRequest>(&decoded.value)) {
            return fp::encode_response(
                fp::WriteSingleResponse{fp::fc::write_single_register, single->address, single->value});
        }
        if (const auto* multiple = std::get_if<fp::WriteMultipleRegistersRequest>(&decoded.value)) {
            return fp::encode_response(fp::WriteMultipleResponse{
                fp::fc::write_multiple_registers, multiple->address,
                static_cast<std::uint16_t>(multiple->values.size())});
        }
        FAIL("the test device does not implement function " << int{frame.pdu[0]});
        return {};
    }

    asio::io_context& io_;
    std::filesystem::path link_;
    std::unique_ptr<asio::posix::stream_descriptor> master_;
    int slave_fd_ = -1;
    Bytes rx_;
    std::vector<fp::RtuFrame> requests_;
    std::size_t bytes_received_ = 0;
    std::size_t unframed_ = 0;
    std::shared_ptr<char> alive_ = std::make_shared<char>('\0');
};

/// A worker on a pty device with short timeouts, and everything a test looks at.
struct Bench {
    explicit Bench(fe::LineTimingConfig timing = short_timing(), unsigned read_retries = 1,
                   std::size_t devices = 2)
        : device(io, dir.path() / "ttyTEST") {
        fe::LineWorkerConfig config;
        config.name = "A";
        config.timing = timing;
        config.reopen_initial = 20ms;
        config.reopen_max = 80ms;
        fe::SerialSettings settings;
        settings.path = device.link().string();
        worker = std::make_unique<fe::LineWorker>(io, config, std::make_unique<fe::PosixSerialPort>(settings),
                                                  logs.sink());
        fe::DeviceLimits limits;
        limits.read_retries = read_retries;
        limits.offline_after = 10;
        for (std::size_t d = 0; d < devices; ++d) {
            worker->scheduler().add_device(static_cast<fe::DeviceIndex>(d), limits);
        }
        worker->set_state_callback([this](bool up, fe::TimePoint) { states.push_back(up); });
    }

    static fe::LineTimingConfig short_timing() {
        fe::LineTimingConfig timing;
        timing.response_timeout = 30ms;
        return timing;
    }

    void start() {
        worker->start();
        REQUIRE(worker->line_up());
    }

    TempDir dir;
    asio::io_context io;
    PtyDevice device;
    LogCapture logs;
    Recorder recorder;
    std::vector<bool> states;
    std::unique_ptr<fe::LineWorker> worker;
};

}  // namespace worker_test
