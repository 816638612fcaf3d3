#include "upstream_test_support.hpp"

#include <array>
#include <fmt/format.h>

#include <asio/write.hpp>

#include "protocol/mbap_frame.hpp"

namespace fbtest {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::uint16_t free_port() {
    asio::io_context io;
    asio::ip::tcp::acceptor a(io, asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    return a.local_endpoint().port();
}


fieldbridge::config::UpstreamConfig config_for(std::uint16_t port) {
    using std::chrono::milliseconds;
    fieldbridge::config::UpstreamConfig c;
    c.name = "r6";
    c.host = "127.0.0.1";
    c.port = port;
    c.connect_timeout = milliseconds{500};
    c.response_timeout = milliseconds{500};
    c.reconnect_backoff = {milliseconds{20}, milliseconds{200}};
    c.poll_period = milliseconds{100};
    c.command_ttl = milliseconds{2000};
    c.queue_limit = 64;
    c.units = {{fieldbridge::core::UnitId{10}, fieldbridge::core::UnitId{1}, "robot"}};
    return c;
}

fieldbridge::engine::LogSink CapturedLog::sink(fieldbridge::engine::LogLevel min) const {
    auto store = lines;
    return {[store](fieldbridge::engine::LogLevel level, std::string_view text) {
                store->push_back(fmt::format("[{}] {}", fieldbridge::engine::to_string(level), text));
            },
            min};
}

bool CapturedLog::contains(const std::string& text) const {
    for (const auto& l : *lines) {
        if (l.find(text) != std::string::npos) return true;
    }
    return false;
}

fieldbridge::northbound::PduHandler capture(std::shared_ptr<Answer> answer) {
    return [answer](Bytes pdu) {
        answer->done = true;
        answer->pdu = std::move(pdu);
        ++answer->calls;
    };
}

Bytes hex(const std::string& text) {
    Bytes out;
    std::size_t i = 0;
    while (i < text.size()) {
        if (text[i] == ' ') {
            ++i;
            continue;
        }
        out.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
        i += 2;
    }
    return out;
}

std::string to_hex(const Bytes& bytes) {
    std::string out;
    for (const auto b : bytes) out += fmt::format("{}{:02x}", out.empty() ? "" : " ", b);
    return out;
}

// ---- FakeUpstream -------------------------------------------------------------

FakeUpstream::FakeUpstream(asio::io_context& io, OnRequest on_request)
    : acceptor_(io, asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0)),
      chunk_(std::make_shared<std::array<std::uint8_t, 1024>>()), on_request_(std::move(on_request)) {
    accept();
}

FakeUpstream::~FakeUpstream() {
    *alive_ = false;
    asio::error_code ignored;
    acceptor_.close(ignored);
    if (socket_) socket_->close(ignored);
}

std::uint16_t FakeUpstream::port() const { return acceptor_.local_endpoint().port(); }

void FakeUpstream::accept() {
    auto alive = alive_;
    acceptor_.async_accept([this, alive](const asio::error_code& ec, asio::ip::tcp::socket socket) {
        if (ec || !*alive) return;
        ++connections_;
        socket_ = std::make_shared<asio::ip::tcp::socket>(std::move(socket));
        received_.clear();
        read();
        accept();
    });
}

void FakeUpstream::read() {
    auto alive = alive_;
    auto socket = socket_;
    auto chunk = chunk_;
    socket->async_read_some(asio::buffer(*chunk), [this, alive, socket, chunk](const asio::error_code& ec, std::size_t n) {
        if (ec || !*alive || socket != socket_) return;
        received_.insert(received_.end(), chunk->begin(), chunk->begin() + static_cast<std::ptrdiff_t>(n));
        for (;;) {
            auto frame = fieldbridge::protocol::decode_mbap(received_);
            if (!frame.complete()) break;
            received_.erase(received_.begin(), received_.begin() + static_cast<std::ptrdiff_t>(frame.consumed));
            Request r{frame.value.transaction_id, frame.value.unit_id.value, frame.value.pdu};
            requests_.push_back(r);
            on_request_(*this, r);
            if (!*alive) return;
        }
        read();
    });
}

void FakeUpstream::send(std::uint16_t transaction_id, std::uint8_t unit, const Bytes& pdu) {
    if (!socket_) return;
    auto frame = std::make_shared<Bytes>(fieldbridge::protocol::encode_mbap(transaction_id, fieldbridge::core::UnitId{unit}, pdu));
    asio::async_write(*socket_, asio::buffer(*frame), [frame](const asio::error_code&, std::size_t) {});
}

}  // namespace fbtest
