#pragma once
// Fake unit targets for the server tests. They run on the loop thread; tests read
// them through Harness::on_loop().
#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <cstdint>
#include <list>
#include <stdexcept>
#include <utility>
#include <vector>

#include "northbound/unit_target.hpp"
#include "register_bank.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {

/// What every fake records.
class RecordingTarget : public UnitTarget {
public:
    using UnitTarget::handle;
    void client_closed(std::uint64_t connection) override { closed.push_back(connection); }
    std::vector<protocol::Bytes> seen;        ///< request PDUs, in arrival order
    std::vector<std::uint64_t> closed;        ///< client_closed calls
    std::vector<ClientRef> clients;           ///< who sent each request
protected:
    void record(protocol::ByteView pdu, const ClientRef& client) {
        seen.emplace_back(pdu.begin(), pdu.end());
        clients.push_back(client);
    }
};

/// Answers from a register bank, posted (never inside handle()).
class ImmediateTarget final : public RecordingTarget {
public:
    explicit ImmediateTarget(asio::io_context& io) : io_(io) {}
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
    RegisterBank bank;
private:
    asio::io_context& io_;
};

/// Answers from a register bank after as many milliseconds as the first register
/// address says (FC03/04), so a test orders answers by address.
class DelayedTarget final : public RecordingTarget {
public:
    /// @p answer_closed: also answer requests whose connection closed (a late answer).
    DelayedTarget(asio::io_context& io, bool answer_closed = false) : io_(io), answer_closed_(answer_closed) {}
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
    void client_closed(std::uint64_t connection) override;
    RegisterBank bank;
private:
    struct Pending {
        asio::steady_timer timer;
        std::uint64_t connection;
    };
    asio::io_context& io_;
    bool answer_closed_;
    std::list<Pending> pending_;
};

/// Keeps every request until answer_all(); client_closed drops that client's ones.
class SilentTarget final : public RecordingTarget {
public:
    explicit SilentTarget(asio::io_context& /*io*/) {}
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
    void client_closed(std::uint64_t connection) override;
    /// Answers everything held, from the bank; returns how many.
    std::size_t answer_all();
    [[nodiscard]] std::size_t holding() const noexcept { return held_.size(); }
    RegisterBank bank;
private:
    struct Held {
        std::uint64_t connection;
        protocol::Bytes pdu;
        PduHandler done;
    };
    std::vector<Held> held_;
};

/// Throws from handle().
class ThrowingTarget final : public RecordingTarget {
public:
    explicit ThrowingTarget(asio::io_context& /*io*/) {}
    void handle(core::UnitId, const RequestPdu& request, const ClientRef& client, PduHandler) override {
        const protocol::ByteView pdu = request.bytes;
        record(pdu, client);
        throw std::runtime_error("fake target failure");
    }
};

/// Answers an empty PDU (a target bug).
class EmptyAnswerTarget final : public RecordingTarget {
public:
    explicit EmptyAnswerTarget(asio::io_context& io) : io_(io) {}
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
private:
    asio::io_context& io_;
};

}  // namespace fieldbridge::northbound::modbus_tcp::test
