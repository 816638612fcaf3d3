#include "fake_targets.hpp"

#include <algorithm>
#include <asio/post.hpp>
#include <chrono>

namespace fieldbridge::northbound::modbus_tcp::test {

void ImmediateTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& client, PduHandler done) {
    const protocol::ByteView pdu = request.bytes;
    record(pdu, client);
    asio::post(io_, [done = std::move(done), answer = bank.answer(pdu)]() mutable { done(std::move(answer)); });
}

void DelayedTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& client, PduHandler done) {
    const protocol::ByteView pdu = request.bytes;
    record(pdu, client);
    const auto delay = pdu.size() >= 3 ? std::chrono::milliseconds{protocol::get_u16_be(pdu, 1)} : std::chrono::milliseconds{0};
    pending_.push_back(Pending{asio::steady_timer(io_, delay), client.connection});
    const auto it = std::prev(pending_.end());
    it->timer.async_wait([this, it, done = std::move(done), answer = bank.answer(pdu)](const asio::error_code& error) mutable {
        if (error) return;  // the target is going away
        pending_.erase(it);
        done(std::move(answer));
    });
}

void DelayedTarget::client_closed(std::uint64_t connection) {
    RecordingTarget::client_closed(connection);
    if (answer_closed_) return;
    for (auto it = pending_.begin(); it != pending_.end();) {
        if (it->connection == connection) {
            it->timer.cancel();
            it = pending_.erase(it);
        } else {
            ++it;
        }
    }
}

void SilentTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& client, PduHandler done) {
    const protocol::ByteView pdu = request.bytes;
    record(pdu, client);
    held_.push_back(Held{client.connection, protocol::Bytes(pdu.begin(), pdu.end()), std::move(done)});
}

void SilentTarget::client_closed(std::uint64_t connection) {
    RecordingTarget::client_closed(connection);
    std::erase_if(held_, [connection](const Held& held) { return held.connection == connection; });
}

std::size_t SilentTarget::answer_all() {
    auto held = std::move(held_);
    held_.clear();
    for (auto& request : held) request.done(bank.answer(request.pdu));
    return held.size();
}

void EmptyAnswerTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& client, PduHandler done) {
    const protocol::ByteView pdu = request.bytes;
    record(pdu, client);
    asio::post(io_, [done = std::move(done)]() mutable { done(protocol::Bytes{}); });
}

}  // namespace fieldbridge::northbound::modbus_tcp::test
