#include "northbound/mqtt/command_runner.hpp"

#include <asio/post.hpp>

#include <array>
#include <cstdio>
#include <type_traits>
#include <utility>
#include <variant>

namespace fieldbridge::northbound::mqtt {

namespace {

std::string hex(unsigned value, int width) {
    std::array<char, 12> text{};
    std::snprintf(text.data(), text.size(), "0x%0*X", width, value);
    return text.data();
}

/// One command in progress: the source, what is left to send, the callback.
struct Run : std::enable_shared_from_this<Run> {
    std::shared_ptr<DeviceSource> source;
    std::vector<protocol::Request> requests;
    std::function<void(CommandOutcome)> done;
    std::size_t next = 0;

    void step() {
        if (next == requests.size()) {
            finish(CommandOutcome{});
            return;
        }
        const std::size_t index = next++;
        source->execute(requests[index], [self = shared_from_this(), index](const protocol::Response& response) {
            CommandOutcome outcome = outcome_of(response, self->source->type());
            if (!outcome.ok) {
                if (index > 0) {
                    outcome.message += "; the " + std::to_string(index) + " request(s) before it were executed";
                }
                self->finish(std::move(outcome));
                return;
            }
            self->step();
        });
    }

    void finish(CommandOutcome outcome) {
        auto callback = std::move(done);
        done = nullptr;
        if (callback) callback(std::move(outcome));
    }
};

}  // namespace

std::string describe(const protocol::Request& request) {
    return std::visit(
        [](const auto& r) -> std::string {
            using R = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<R, protocol::WriteSingleRegisterRequest>) {
                return "FC06 " + hex(r.address, 4) + " = " + std::to_string(r.value);
            } else if constexpr (std::is_same_v<R, protocol::WriteMultipleRegistersRequest>) {
                return "FC16 " + hex(r.address, 4) + " x" + std::to_string(r.values.size());
            } else if constexpr (std::is_same_v<R, protocol::WriteSingleCoilRequest>) {
                return "FC05 " + hex(r.address, 4) + " = " + (r.value ? "on" : "off");
            } else if constexpr (std::is_same_v<R, protocol::WriteMultipleCoilsRequest>) {
                return "FC15 " + hex(r.address, 4) + " x" + std::to_string(r.values.size());
            } else {
                return "FC" + hex(protocol::function_code(protocol::Request{r}).value, 2).substr(2);
            }
        },
        request);
}

CommandOutcome outcome_of(const protocol::Response& response, std::string_view device_type) {
    const auto* exception = std::get_if<protocol::ExceptionResponse>(&response);
    if (exception == nullptr) {
        return CommandOutcome{};
    }
    CommandOutcome outcome;
    outcome.ok = false;
    outcome.exception = exception->code;
    const std::string text = exception_text(exception->code);
    switch (exception->code) {
        case protocol::ExceptionCode::gateway_target_failed:
            outcome.error = "no_answer";
            outcome.message = "the device did not answer, or the command could not start before its deadline (" +
                              text + "); check the device and the line";
            break;
        case protocol::ExceptionCode::server_device_busy:
            outcome.error = "busy";
            outcome.message = "the device's queue is full (" + text + "); send it again later";
            break;
        case protocol::ExceptionCode::gateway_path_unavailable:
            outcome.error = "unavailable";
            outcome.message = "the device's line is down or being reconfigured (" + text + ")";
            break;
        case protocol::ExceptionCode::server_device_failure:
            if (device_type == engine::to_string(engine::DeviceType::wtec_ascii)) {
                // The ASCII protocol has no exceptions: the view answers 0x04 when the
                // gripper echoed `D` / `E` back instead of acting (seed 003 command 9).
                outcome.error = "not_executed";
                outcome.message = "the gripper did not execute the command (it echoed it back: motor released "
                                  "or not homed; " + text + "); initialise it (op init) and send it again";
                break;
            }
            [[fallthrough]];
        default:
            outcome.error = "device_exception";
            outcome.message = "the device answered " + text;
            break;
    }
    return outcome;
}

void run_command(asio::io_context& io, std::shared_ptr<DeviceSource> source,
                 std::vector<protocol::Request> requests, std::function<void(CommandOutcome)> done) {
    for (const protocol::Request& request : requests) {
        if (const auto code = source->validate(request)) {
            CommandOutcome outcome;
            outcome.ok = false;
            outcome.error = "rejected";
            outcome.exception = *code;
            outcome.message = "the " + std::string(source->type()) + " profile refuses " + describe(request) + ": " +
                              exception_text(*code) + "; nothing was sent";
            asio::post(io, [done = std::move(done), outcome = std::move(outcome)]() mutable { done(std::move(outcome)); });
            return;
        }
    }
    auto run = std::make_shared<Run>();
    run->source = std::move(source);
    run->requests = std::move(requests);
    run->done = std::move(done);
    run->step();
}

}  // namespace fieldbridge::northbound::mqtt
