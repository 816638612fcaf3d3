#include "northbound/targets/line_broadcast_target.hpp"

#include <algorithm>
#include <iterator>
#include <numeric>

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
    BroadcastBudget budget;                    ///< every broadcast of the line
    BroadcastBudget stop_budget;               ///< stops only (rule 4): they never wait for the other
    std::vector<std::shared_ptr<Operation>> held_stops;  ///< over the stops' budget, oldest first
    asio::steady_timer stop_timer;
    bool stop_timer_armed = false;

    Shared(asio::io_context& context, engine::LineWorker& worker, const BroadcastSettings& settings)
        : io(context),
          line(&worker),
          command_ttl(settings.command_ttl),
          budget(settings.share_percent),
          stop_budget(settings.share_percent),
          stop_timer(context) {}
};

/// One broadcast on its way: its steps, the next one, and who to answer.
struct LineBroadcastTarget::Operation {
    protocol::Request request;
    protocol::Bytes request_pdu;  ///< as the client sent it: identical stops are one frame
    std::vector<BroadcastStep> steps;
    std::vector<engine::Duration> step_costs;  ///< line time of each step, charged to the budget
    std::size_t next = 0;
    bool stop = false;
    core::FunctionCode function;
    protocol::Bytes echo;
    std::vector<PduHandler> waiting;  ///< the client, and the clients of identical stops held with it

    void answer(asio::io_context& io, const protocol::Bytes& pdu) {
        // Never from inside handle() or the line's completion (unit_target.hpp).
        for (PduHandler& done : waiting) {
            asio::post(io, [done = std::move(done), pdu]() mutable { done(pdu); });
        }
        waiting.clear();
    }
    /// The cost of the steps not sent yet.
    [[nodiscard]] engine::Duration unsent_cost() const {
        return std::accumulate(step_costs.begin() + static_cast<std::ptrdiff_t>(next), step_costs.end(),
                               engine::Duration{});
    }
};

LineBroadcastTarget::LineBroadcastTarget(asio::io_context& io, engine::LineWorker& line, std::vector<LineUnit> devices,
                                         BroadcastSettings settings)
    : shared_(std::make_shared<Shared>(io, line, settings)), devices_(std::move(devices)) {
    for (const LineUnit& device : devices_) {
        units_.push_back(device.unit_id);
        shared_->agents.push_back(device.agent);
    }
}

LineBroadcastTarget::~LineBroadcastTarget() {
    shared_->line = nullptr;
    shared_->agents.clear();
    shared_->stop_timer.cancel();
    for (const std::shared_ptr<Operation>& op : shared_->held_stops) {
        op->answer(shared_->io, protocol::exception_pdu(op->function, GatewayRefusal::path_down));
    }
    shared_->held_stops.clear();
}

std::vector<engine::Duration> LineBroadcastTarget::line_time(const std::vector<BroadcastStep>& steps) const {
    const engine::LineTimingConfig& timing = shared_->line->config().timing;
    const engine::LineTiming wire(timing.format(), timing.inter_frame);
    std::vector<engine::Duration> costs;
    costs.reserve(steps.size());
    for (const BroadcastStep& step : steps) {
        const std::size_t frame =
            protocol::encode_request(std::get<engine::ModbusPayload>(step.payload).request).size() + rtu_overhead;
        costs.push_back(step.delay_before + wire.transaction_time(frame, 0, timing.broadcast_delay));
    }
    return costs;
}

void LineBroadcastTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& /*client*/,
                                 PduHandler done) {
    asio::io_context& io = shared_->io;
    auto op = std::make_shared<Operation>();
    op->function = request.function();
    op->waiting.push_back(std::move(done));
    const auto refuse = [&](const protocol::Bytes& pdu) { op->answer(io, pdu); };
    const auto& decoded = request.decoded;
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
    op->stop = std::all_of(plan.steps.begin(), plan.steps.end(), [](const BroadcastStep& step) { return step.urgent; });
    op->step_costs = line_time(plan.steps);
    op->request = decoded.value;
    op->request_pdu.assign(request.bytes.begin(), request.bytes.end());
    op->steps = std::move(plan.steps);
    op->echo = protocol::encode_response(*echo);
    if (op->stop) {
        send_stop(shared_, op);
        return;
    }
    if (!shared_->budget.take(op->unsent_cost(), engine::Clock::now())) {
        refuse(protocol::exception_pdu(op->function, GatewayRefusal::busy));
        return;
    }
    submit_step(shared_, op);
}

void LineBroadcastTarget::send_stop(const std::shared_ptr<Shared>& shared, const std::shared_ptr<Operation>& op) {
    for (const std::shared_ptr<Operation>& held : shared->held_stops) {
        if (held->request_pdu == op->request_pdu) {
            // The same frame is already waiting: it answers this client too.
            std::move(op->waiting.begin(), op->waiting.end(), std::back_inserter(held->waiting));
            return;
        }
    }
    const engine::TimePoint now = engine::Clock::now();
    if (shared->held_stops.empty() && shared->stop_budget.take(op->unsent_cost(), now)) {
        shared->budget.charge(op->unsent_cost(), now);
        submit_step(shared, op);
        return;
    }
    shared->held_stops.push_back(op);
    arm_stop_timer(shared);
}

void LineBroadcastTarget::release_held_stops(const std::shared_ptr<Shared>& shared) {
    const engine::TimePoint now = engine::Clock::now();
    while (!shared->held_stops.empty() && shared->stop_budget.take(shared->held_stops.front()->unsent_cost(), now)) {
        std::shared_ptr<Operation> op = std::move(shared->held_stops.front());
        shared->held_stops.erase(shared->held_stops.begin());
        shared->budget.charge(op->unsent_cost(), now);
        submit_step(shared, op);
    }
    if (!shared->held_stops.empty()) arm_stop_timer(shared);
}

void LineBroadcastTarget::arm_stop_timer(const std::shared_ptr<Shared>& shared) {
    if (shared->stop_timer_armed) return;
    shared->stop_timer_armed = true;
    shared->stop_timer.expires_at(shared->stop_budget.available_at(engine::Clock::now()));
    shared->stop_timer.async_wait([weak = std::weak_ptr<Shared>(shared)](const std::error_code& error) {
        const std::shared_ptr<Shared> alive = weak.lock();
        if (error || !alive || alive->line == nullptr) return;
        alive->stop_timer_armed = false;
        release_held_stops(alive);
    });
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
            // Not on the line: what it reserved is given back (only what was sent is charged).
            const engine::TimePoint now = engine::Clock::now();
            shared->budget.refund(op->unsent_cost(), now);
            if (op->stop) shared->stop_budget.refund(op->unsent_cost(), now);
            op->answer(shared->io, protocol::exception_pdu(op->function, engine::refusal_for(outcome.status)));
            return;
        }
        if (++op->next == op->steps.size()) {
            for (engine::DeviceAgent* agent : shared->agents) agent->broadcast_written(op->request);
            op->answer(shared->io, op->echo);
            return;
        }
        submit_step(shared, op);
    };
    shared->line->submit(std::move(transaction));
}

}  // namespace fieldbridge::northbound
