#include "engine/profiles/modbus_profile.hpp"

#include <algorithm>
#include <type_traits>
#include <utility>
#include <variant>

#include "protocol/gateway_exceptions.hpp"

namespace fieldbridge::engine {

namespace {

using protocol::ExceptionCode;

[[nodiscard]] protocol::Response failure(core::FunctionCode function, ExceptionCode code) {
    return protocol::exception_response(function, code);
}

[[nodiscard]] bool is_write_ack(const Reply& reply) {
    const auto* r = std::get_if<protocol::Response>(&reply);
    return r != nullptr && (std::holds_alternative<protocol::WriteSingleResponse>(*r) ||
                            std::holds_alternative<protocol::WriteMultipleResponse>(*r));
}

}  // namespace

ModbusProfile::ModbusProfile(std::shared_ptr<const RegisterMap> map, WireFunctions wire, ProfileOptions options,
                             WordOrder word_order)
    : map_(std::move(map)), wire_(std::move(wire)), options_(std::move(options)), word_order_(word_order) {}

std::optional<ExceptionCode> ModbusProfile::check_value(const RegisterDef& /*def*/, std::uint16_t /*unit_address*/,
                                                        std::int64_t /*value*/,
                                                        const RegisterImage& /*image*/) const {
    return std::nullopt;
}

void ModbusProfile::on_device_exception(const protocol::Request& /*sent*/, ExceptionCode /*code*/,
                                        ApplyResult& /*result*/) const {}

void ModbusProfile::apply_other(const protocol::Request& /*sent*/, const protocol::Response& /*reply*/,
                                RegisterImage& /*image*/, TimePoint /*now*/, ApplyResult& result) const {
    result.status = ApplyStatus::not_applicable;
}

Duration ModbusProfile::period_of(PollClass poll_class) const noexcept {
    switch (poll_class) {
        case PollClass::fast: return options_.poll.fast;
        case PollClass::slow: return options_.poll.slow;
        case PollClass::startup:
        case PollClass::custom: break;
    }
    return Duration{};
}

std::vector<PollUnit> ModbusProfile::units_for(Table table, std::uint16_t address, std::uint16_t count,
                                               PollClass poll_class, bool motion) const {
    return map_->poll_units(RegisterSpan{table, address, count}, poll_class, period_of(poll_class), motion);
}

std::optional<ExceptionCode> ModbusProfile::validate(const protocol::Request& request,
                                                     const RegisterImage& image) const {
    return validate_request(*map_, request, wire_.northbound, options_.allow_protected,
                            [this, &image](const RegisterDef& def, std::uint16_t address, std::int64_t value) {
                                return check_value(def, address, value, image);
                            });
}

Classification ModbusProfile::classify(const protocol::Request& request) const {
    return classify_request(*map_, request);
}

PollPlan ModbusProfile::poll_plan() const {
    return PollPlan{merge_units(poll_units())};
}

void ModbusProfile::swap_pairs(Table table, std::uint16_t address, std::span<std::uint16_t> values,
                               std::vector<bool>* partial) const {
    const std::size_t end = std::size_t{address} + values.size();
    for (const UnitRef& u : map_->units(table, address, static_cast<std::uint16_t>(values.size()))) {
        if (u.def->width != 2) {
            continue;
        }
        if (u.address < address || std::size_t{u.address} + 2 > end) {
            // Half a pair at an edge: its other word is not here, so neither its
            // place nor its meaning is known.
            if (partial != nullptr) {
                for (std::size_t a = u.address; a < std::size_t{u.address} + 2; ++a) {
                    if (a >= address && a < end) {
                        (*partial)[a - address] = true;
                    }
                }
            }
            continue;
        }
        const std::size_t i = u.address - address;
        std::swap(values[i], values[i + 1]);
    }
}

std::vector<Payload> ModbusProfile::to_line(const protocol::Request& request, const RegisterImage& /*image*/) const {
    std::vector<Payload> out;
    std::visit(
        [&](const auto& r) {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, protocol::ReadRegistersRequest>) {
                const Table table = table_of_read(protocol::function_code(r));
                const std::vector<UnitRef> units = map_->units(table, r.address, r.count);
                if (!swaps() || units.empty()) {
                    out.push_back(ModbusPayload{r});
                    return;
                }
                // Low word first on the wire: a read that cuts a pair is widened to
                // the whole pair, so the pair can be put back in northbound order.
                const std::size_t first = std::min<std::size_t>(r.address, units.front().address);
                const std::size_t last = std::max<std::size_t>(std::size_t{r.address} + r.count,
                                                               std::size_t{units.back().address} +
                                                                   units.back().def->width);
                if (last - first <= protocol::max_read_registers) {
                    out.push_back(ModbusPayload{protocol::ReadRegistersRequest{
                        r.function, static_cast<std::uint16_t>(first), static_cast<std::uint16_t>(last - first)}});
                    return;
                }
                // Widening went past 125: two reads, split at a unit boundary.
                const UnitRef& mid = units[units.size() / 2];
                out.push_back(ModbusPayload{protocol::ReadRegistersRequest{
                    r.function, static_cast<std::uint16_t>(first), static_cast<std::uint16_t>(mid.address - first)}});
                out.push_back(ModbusPayload{protocol::ReadRegistersRequest{
                    r.function, mid.address, static_cast<std::uint16_t>(last - mid.address)}});
            } else if constexpr (std::is_same_v<T, protocol::WriteSingleRegisterRequest>) {
                if (wire_.fc06_as_fc16) {
                    // Seed 001 §4.1: the XEG controller knows FC03/04/02/07/10 only.
                    out.push_back(ModbusPayload{protocol::WriteMultipleRegistersRequest{r.address, {r.value}}});
                } else {
                    out.push_back(ModbusPayload{r});
                }
            } else if constexpr (std::is_same_v<T, protocol::WriteMultipleRegistersRequest>) {
                std::vector<std::uint16_t> values = r.values;
                if (swaps()) {
                    swap_pairs(Table::holding, r.address, values, nullptr);
                }
                if (wire_.fc16_as_fc06) {
                    for (std::size_t i = 0; i < values.size(); ++i) {
                        out.push_back(ModbusPayload{protocol::WriteSingleRegisterRequest{
                            static_cast<std::uint16_t>(r.address + i), values[i]}});
                    }
                } else {
                    out.push_back(ModbusPayload{protocol::WriteMultipleRegistersRequest{r.address, std::move(values)}});
                }
            } else {
                out.push_back(ModbusPayload{r});
            }
        },
        request);
    return out;
}

void ModbusProfile::store(RegisterImage& image, Table table, std::uint16_t address, std::vector<std::uint16_t> values,
                          bool wire_order, bool written, TimePoint now) const {
    std::vector<bool> skip(values.size(), false);
    if (wire_order && swaps()) {
        swap_pairs(table, address, values, &skip);
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
        // Registers outside the map (the gaps a generic device's merged read bridges,
        // docs/registers.md) are no value of the device: not kept.
        const RegisterDef* def = map_->find(table, static_cast<std::uint16_t>(address + i));
        if (def == nullptr) {
            skip[i] = true;
        } else if (written) {
            // A write-only register is a command, not a value a read would return.
            if (!can_read(def->access)) {
                skip[i] = true;
            } else if (def->auto_reset) {
                // Seed 001 §3.4 "Auto Reset": the controller sets it back to 0 once it
                // has acted, so 0 is what a read returns.
                values[i] = 0;
            }
        }
    }
    std::size_t i = 0;
    while (i < values.size()) {
        if (skip[i]) {
            ++i;
            continue;
        }
        std::size_t j = i;
        while (j < values.size() && !skip[j]) {
            ++j;
        }
        image.update(table, static_cast<std::uint16_t>(address + i),
                     std::span<const std::uint16_t>(values.data() + i, j - i), now);
        i = j;
    }
}

ApplyResult ModbusProfile::apply(const Payload& sent, const Reply& reply, RegisterImage& image, TimePoint now) const {
    ApplyResult result;
    const auto* payload = std::get_if<ModbusPayload>(&sent);
    const auto* response = std::get_if<protocol::Response>(&reply);
    if (payload == nullptr || response == nullptr) {
        result.status = ApplyStatus::not_applicable;
        return result;
    }
    const protocol::Request& req = payload->request;
    if (const auto* ex = std::get_if<protocol::ExceptionResponse>(response)) {
        if (protocol::function_code(*ex) != protocol::function_code(req)) {
            result.status = ApplyStatus::not_applicable;
            return result;
        }
        result.status = ApplyStatus::device_exception;
        result.exception = ex->code;
        if (const auto span = request_span(req); span && !span->write) {
            image.mark_stale(span->table, span->address, span->count);
        }
        on_device_exception(req, ex->code, result);
        return result;
    }
    bool handled = true;
    std::visit(
        [&](const auto& r) {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, protocol::ReadBitsRequest>) {
                const auto* bits = std::get_if<protocol::ReadBitsResponse>(response);
                if (bits == nullptr || protocol::function_code(*bits) != protocol::function_code(r) || bits->bits.size() < r.count) {
                    handled = false;
                    return;
                }
                std::vector<std::uint16_t> values(r.count);
                for (std::size_t i = 0; i < r.count; ++i) {
                    values[i] = bits->bits[i] ? 1 : 0;
                }
                const Table table = table_of_read(protocol::function_code(r));
                store(image, table, r.address, std::move(values), false, false, now);
            } else if constexpr (std::is_same_v<T, protocol::ReadRegistersRequest>) {
                const auto* regs = std::get_if<protocol::ReadRegistersResponse>(response);
                if (regs == nullptr || protocol::function_code(*regs) != protocol::function_code(r) || regs->values.size() != r.count) {
                    handled = false;
                    return;
                }
                const Table table = table_of_read(protocol::function_code(r));
                store(image, table, r.address, regs->values, true, false, now);
            } else if constexpr (std::is_same_v<T, protocol::WriteSingleRegisterRequest> ||
                                 std::is_same_v<T, protocol::WriteSingleCoilRequest> ||
                                 std::is_same_v<T, protocol::WriteMultipleRegistersRequest> ||
                                 std::is_same_v<T, protocol::WriteMultipleCoilsRequest>) {
                if (!is_write_ack(reply)) {
                    handled = false;
                    return;
                }
                const std::optional<RequestSpan> span = request_span(req);
                store(image, span->table, span->address, span->values, true, true, now);
            } else if constexpr (std::is_same_v<T, protocol::MaskWriteRegisterRequest>) {
                if (!std::holds_alternative<protocol::MaskWriteResponse>(*response)) {
                    handled = false;
                    return;
                }
                // What the register holds now depends on what it held: read it again.
                image.mark_stale(Table::holding, r.address, 1);
            } else if constexpr (std::is_same_v<T, protocol::ReadWriteRegistersRequest>) {
                const auto* regs = std::get_if<protocol::ReadRegistersResponse>(response);
                if (regs == nullptr || protocol::function_code(*regs) != protocol::function_code(r) ||
                    regs->values.size() != r.read_count) {
                    handled = false;
                    return;
                }
                // FC17 writes first, then reads (Modbus Application Protocol 6.17).
                store(image, Table::holding, r.write_address, r.values, true, true, now);
                store(image, Table::holding, r.read_address, regs->values, true, false, now);
            } else {
                handled = false;
            }
        },
        req);
    if (!handled) {
        apply_other(req, *response, image, now, result);
    }
    return result;
}

protocol::Response ModbusProfile::respond(const protocol::Request& request, std::span<const Reply> replies,
                                          const RegisterImage& image) const {
    const core::FunctionCode function = protocol::function_code(request);
    for (const Reply& reply : replies) {
        const auto* response = std::get_if<protocol::Response>(&reply);
        if (response == nullptr) {
            return failure(function, ExceptionCode::gateway_target_failed);
        }
        if (const auto* ex = std::get_if<protocol::ExceptionResponse>(response)) {
            // Spec §4: device exceptions are passed through unchanged, under the
            // function code the client used (XEG FC06 went out as FC16).
            return failure(function, ex->code);
        }
    }
    const std::vector<Payload> payloads = to_line(request, image);
    if (replies.empty() || payloads.size() != replies.size()) {
        return failure(function, ExceptionCode::gateway_target_failed);
    }
    const auto& first = std::get<protocol::Response>(replies.front());
    return std::visit(
        [&](const auto& r) -> protocol::Response {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, protocol::ReadBitsRequest>) {
                const auto* bits = std::get_if<protocol::ReadBitsResponse>(&first);
                if (bits == nullptr || bits->bits.size() < r.count) {
                    return failure(function, ExceptionCode::gateway_target_failed);
                }
                return protocol::ReadBitsResponse{r.function,
                                                  std::vector<bool>(bits->bits.begin(), bits->bits.begin() + r.count)};
            } else if constexpr (std::is_same_v<T, protocol::ReadRegistersRequest>) {
                const Table table = table_of_read(protocol::function_code(r));
                std::vector<std::uint16_t> out(r.count);
                std::vector<bool> filled(r.count, false);
                for (std::size_t k = 0; k < payloads.size(); ++k) {
                    const auto& sent = std::get<protocol::ReadRegistersRequest>(
                        std::get<ModbusPayload>(payloads[k]).request);
                    const auto* regs = std::get_if<protocol::ReadRegistersResponse>(
                        &std::get<protocol::Response>(replies[k]));
                    if (regs == nullptr || regs->values.size() != sent.count) {
                        return failure(function, ExceptionCode::gateway_target_failed);
                    }
                    std::vector<std::uint16_t> values = regs->values;
                    if (swaps()) {
                        swap_pairs(table, sent.address, values, nullptr);
                    }
                    for (std::size_t i = 0; i < values.size(); ++i) {
                        const std::size_t a = std::size_t{sent.address} + i;
                        if (a >= r.address && a < std::size_t{r.address} + r.count) {
                            out[a - r.address] = values[i];
                            filled[a - r.address] = true;
                        }
                    }
                }
                if (std::find(filled.begin(), filled.end(), false) != filled.end()) {
                    return failure(function, ExceptionCode::gateway_target_failed);
                }
                return protocol::ReadRegistersResponse{r.function, std::move(out)};
            } else if constexpr (std::is_same_v<T, protocol::WriteSingleRegisterRequest> ||
                                 std::is_same_v<T, protocol::WriteSingleCoilRequest> ||
                                 std::is_same_v<T, protocol::WriteMultipleRegistersRequest> ||
                                 std::is_same_v<T, protocol::WriteMultipleCoilsRequest>) {
                if (!std::all_of(replies.begin(), replies.end(), is_write_ack)) {
                    return failure(function, ExceptionCode::gateway_target_failed);
                }
                if constexpr (std::is_same_v<T, protocol::WriteSingleRegisterRequest>) {
                    return protocol::WriteSingleResponse{protocol::fc::write_single_register, r.address, r.value};
                } else if constexpr (std::is_same_v<T, protocol::WriteSingleCoilRequest>) {
                    // FC05 echoes ON as 0xFF00 (Modbus Application Protocol §6.5).
                    return protocol::WriteSingleResponse{protocol::fc::write_single_coil, r.address,
                                                         static_cast<std::uint16_t>(r.value ? 0xFF00 : 0x0000)};
                } else {
                    return protocol::WriteMultipleResponse{function.value, r.address,
                                                           static_cast<std::uint16_t>(r.values.size())};
                }
            } else {
                // FC07 and anything passed through: the device's own answer.
                return first;
            }
        },
        request);
}

}  // namespace fieldbridge::engine
