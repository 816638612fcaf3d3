#include "northbound/upstream/request_class.hpp"

#include <variant>


namespace fieldbridge::northbound::upstream {
namespace {

/// The register spans a request reads and writes (holding / input registers only:
/// no R6 sequence lies in its coil table, FC01/05/0F).
RegisterAccess access_of(const protocol::Request& request) {
    RegisterAccess a;
    if (const auto* r = std::get_if<protocol::ReadRegistersRequest>(&request)) {
        a.read_address = r->address;
        a.read_count = r->count;
    } else if (const auto* w = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        a.write_address = w->address;
        a.write_count = 1;
    } else if (const auto* m = std::get_if<protocol::WriteMultipleRegistersRequest>(&request)) {
        a.write_address = m->address;
        a.write_count = static_cast<std::uint32_t>(m->values.size());
    } else if (const auto* rw = std::get_if<protocol::ReadWriteRegistersRequest>(&request)) {
        a.read_address = rw->read_address;
        a.read_count = rw->read_count;
        a.write_address = rw->write_address;
        a.write_count = static_cast<std::uint32_t>(rw->values.size());
    }
    return a;
}

}  // namespace

bool RequestClass::touches_any() const noexcept {
    for (const Role r : roles) {
        if (r != Role::none) return true;
    }
    return false;
}

Classified classify(protocol::ByteView pdu) { return classify(protocol::decode_request(pdu), pdu); }

Classified classify(const protocol::DecodeResult<protocol::Request>& decoded, protocol::ByteView pdu) {
    Classified out;
    if (!decoded.complete()) {
        out.local.refusal = protocol::refusal_for_undecodable(protocol::pdu_function(pdu));
        return out;
    }
    RequestClass c;
    c.priority = protocol::is_write(protocol::function_code(decoded.value)) ? engine::Priority::command
                                                                           : engine::Priority::on_demand;
    const RegisterAccess a = access_of(decoded.value);
    c.urgent = writes_stop(a);
    for (std::size_t r = 0; r < resource_count; ++r) c.roles[r] = role_in(static_cast<Resource>(r), a);
    out.request = c;
    return out;
}

}  // namespace fieldbridge::northbound::upstream
