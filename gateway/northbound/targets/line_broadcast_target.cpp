#include "northbound/targets/line_broadcast_target.hpp"

#include <algorithm>

#include <asio/post.hpp>

#include "engine/device_agent_answers.hpp"
#include "engine/line_timing.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

namespace {

using protocol::GatewayRefusal;

/// What a device would have answered to the write (Modbus 6.5, 6.6, 6.11, 6.12).
std::optional<protocol::Response> write_echo(const protocol::Request& request) {
    using namespace protocol;
    if (const auto* coil = std::get_if<WriteSingleCoilRequest>(&request)) {
        return WriteSingleResponse{fc::write_single_coil, coil->address,
                                   static_cast<std::uint16_t>(coil->value ? 0xFF00 : 0x0000)};
    }
    if (const auto* reg = std::get_if<WriteSingleRegisterRequest>(&request)) {
        return WriteSingleResponse{fc::write_single_register, reg->address, reg->value};
    }
    if (const auto* coils = std::get_if<WriteMultipleCoilsRequest>(&request)) {
        return WriteMultipleResponse{fc::write_multiple_coils, coils->address,
                                     static_cast<std::uint16_t>(coils->values.size())};
    }
    if (const auto* regs = std::get_if<WriteMultipleRegistersRequest>(&request)) {
        return WriteMultipleResponse{fc::write_multiple_registers, regs->address,
                                     static_cast<std::uint16_t>(regs->values.size())};
    }
    return std::nullopt;
}

/// RTU framing around a PDU: address byte and CRC (Modbus over Serial Line 2.5.1).
constexpr std::size_t rtu_overhead = 3;

}  // namespace

/// What the transactions' callbacks share with the target: they may complete after
/// it is gone (then `line` is null and nothing more is submitted).
struct LineBroadcastTarget::Shared {
    asio::io_context& io;
    engine::LineWorker* line;
    engine::Duration command_ttl;
    std::vector<engine::DeviceAgent*> agents;  ///< cleared with `line` when the target goes
};

/// One broadcast on its way: its steps, the next one, and who to answer.
struct LineBroadcastTarget::Operation {
    protocol::Request request;
    std::vector<BroadcastStep> steps;
    std::size_t next = 0;
    core::FunctionCode function;
    protocol::Bytes echo;
    PduHandler done;

    void answer(asio::io_context& io, protocol::Bytes pdu) {
        if (!done) return;
        // Never from inside handle() or the line's completion (unit_target.hpp).
        asio::post(io, [done = std::move(done), pdu = std::move(pdu)]() mutable { done(std::move(pdu)); });
        done = nullptr;
    }
};

LineBroadcastTarget::LineBroadcastTarget(asio::io_context& io, engine::LineWorker& line, std::vector<LineUnit> devices,
                                         BroadcastSettings settings)
    : shared_(std::make_shared<Shared>(Shared{io, &line, settings.command_ttl, {}})),
      devices_(std::move(devices)),
      budget_(settings.share_percent) {
    for (const LineUnit& device : devices_) {
        units_.push_back(device.unit_id);
        shared_->agents.push_back(device.agent);
    }
}

LineBroadcastTarget::~LineBroadcastTarget() {
    shared_->line = nullptr;
    shared_->agents.clear();
}

engine::Duration LineBroadcastTarget::line_time(const std::vector<BroadcastStep>& steps) const {
    const engine::LineTimingConfig& timing = shared_->line->config().timing;
    const engine::LineTiming wire(timing.format(), timing.inter_frame);
    engine::Duration total{};
    for (const BroadcastStep& step : steps) {
        const std::size_t frame =
            protocol::encode_request(std::get<engine::ModbusPayload>(step.payload).request).size() + rtu_overhead;
        total += step.delay_before + wire.transaction_time(frame, 0, timing.broadcast_delay);
    }
    return total;
}

void LineBroadcastTarget::handle(core::UnitId /*unit*/, protocol::ByteView request_pdu, const ClientRef& /*client*/,
                                 PduHandler done) {
    asio::io_context& io = shared_->io;
    auto op = std::make_shared<Operation>();
    op->function = protocol::pdu_function(request_pdu);
    op->done = std::move(done);
    const auto refuse = [&](protocol::Bytes pdu) { op->answer(io, std::move(pdu)); };
    const auto decoded = protocol::decode_request(request_pdu);
    if (!decoded.complete()) {
        refuse(protocol::exception_pdu(op->function, protocol::refusal_for_undecodable(op->function)));
        return;
    }
    const auto echo = write_echo(decoded.value);
    if (!echo) {
        refuse(protocol::exception_pdu(op->function, GatewayRefusal::unsupported));
        return;
    }
    if (!shared_->line->line_up()) {
        refuse(protocol::exception_pdu(op->function, GatewayRefusal::path_down));
        return;
    }
    std::vector<BroadcastMember> members;
    members.reserve(devices_.size());
    for (const LineUnit& device : devices_) {
        members.push_back(BroadcastMember{&device.agent->profile(), &device.agent->image(),
                                          device.agent->config().delay_before_command});
    }
    BroadcastPlan plan = plan_broadcast(decoded.value, members);
    if (plan.refusal) {
        refuse(protocol::exception_pdu(op->function, *plan.refusal));
        return;
    }
    const bool stop = std::all_of(plan.steps.begin(), plan.steps.end(),
                                  [](const BroadcastStep& step) { return step.urgent; });
    if (stop) {
        budget_.charge(line_time(plan.steps), engine::Clock::now());
    } else if (!budget_.take(line_time(plan.steps), engine::Clock::now())) {
        refuse(protocol::exception_pdu(op->function, GatewayRefusal::busy));
        return;
    }
    op->request = decoded.value;
    op->steps = std::move(plan.steps);
    op->echo = protocol::encode_response(*echo);
    submit_step(shared_, op);
}

void LineBroadcastTarget::submit_step(const std::shared_ptr<Shared>& shared, const std::shared_ptr<Operation>& op) {
    if (shared->line == nullptr) {
        op->answer(shared->io, protocol::exception_pdu(op->function, GatewayRefusal::path_down));
        return;
    }
    const BroadcastStep& step = op->steps[op->next];
    engine::Transaction transaction;
    transaction.device = engine::broadcast_device;
    transaction.address = step.address.value;  // the line's Transaction carries the byte
    transaction.payload = step.payload;
    transaction.priority = engine::Priority::command;
    transaction.urgent = step.urgent;          // rule 4
    transaction.delay_before = step.delay_before;  // rule 11
    transaction.deadline = engine::Clock::now() + shared->command_ttl;  // rule 9
    transaction.on_done = [shared, op](const engine::Outcome& outcome) {
        if (outcome.status != engine::OutcomeStatus::broadcast_sent) {
            op->answer(shared->io, protocol::exception_pdu(op->function, engine::refusal_for(outcome.status)));
            return;
        }
        if (++op->next == op->steps.size()) {
            for (engine::DeviceAgent* agent : shared->agents) agent->broadcast_written(op->request);
            op->answer(shared->io, std::move(op->echo));
            return;
        }
        submit_step(shared, op);
    };
    shared->line->submit(std::move(transaction));
}

}  // namespace fieldbridge::northbound
