#include "engine/device_agent_answers.hpp"

#include <type_traits>
#include <variant>
#include <vector>

#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

using protocol::ExceptionCode;

protocol::GatewayRefusal refusal_for(OutcomeStatus status) noexcept {
    using protocol::GatewayRefusal;
    switch (status) {
        case OutcomeStatus::timeout:
        case OutcomeStatus::device_offline: return GatewayRefusal::no_answer;
        case OutcomeStatus::expired: return GatewayRefusal::expired;
        case OutcomeStatus::queue_full: return GatewayRefusal::busy;
        case OutcomeStatus::line_down: return GatewayRefusal::path_down;
        case OutcomeStatus::cancelled: return GatewayRefusal::cancelled;
        case OutcomeStatus::ok:  // an ok outcome without a usable reply
        case OutcomeStatus::broadcast_sent:
        case OutcomeStatus::invalid_request:
        case OutcomeStatus::bad_reply: break;
    }
    return GatewayRefusal::gateway_failure;
}

ExceptionCode exception_for(OutcomeStatus status) noexcept { return protocol::exception_code(refusal_for(status)); }

protocol::Response exception_response(const protocol::Request& request, ExceptionCode code) {
    return protocol::exception_response(protocol::function_code(request), code);
}

protocol::Response exception_response(const protocol::Request& request, protocol::GatewayRefusal refusal) {
    return protocol::exception_response(protocol::function_code(request), refusal);
}

std::optional<protocol::Response> answer_from_image(const protocol::Request& request, const RegisterImage& image,
                                                    TimePoint now, Duration max_age) {
    if (max_age <= Duration{}) {
        return std::nullopt;
    }
    return std::visit(
        [&](const auto& r) -> std::optional<protocol::Response> {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, protocol::ReadRegistersRequest>) {
                const Table table = table_of_read(protocol::function_code(r));
                auto values = image.read_fresh(table, r.address, r.count, now, max_age);
                if (!values) {
                    return std::nullopt;
                }
                return protocol::ReadRegistersResponse{r.function, std::move(*values)};
            } else if constexpr (std::is_same_v<T, protocol::ReadBitsRequest>) {
                const Table table = table_of_read(protocol::function_code(r));
                const auto values = image.read_fresh(table, r.address, r.count, now, max_age);
                if (!values) {
                    return std::nullopt;
                }
                std::vector<bool> bits(values->size());
                for (std::size_t i = 0; i < values->size(); ++i) {
                    bits[i] = (*values)[i] != 0;
                }
                return protocol::ReadBitsResponse{r.function, std::move(bits)};
            } else {
                return std::nullopt;
            }
        },
        request);
}

}  // namespace fieldbridge::engine
