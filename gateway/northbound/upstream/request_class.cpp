#include "northbound/upstream/request_class.hpp"

#include <variant>

#include "northbound/upstream/r6_map.hpp"

namespace fieldbridge::northbound::upstream {
namespace {

using protocol::ExceptionCode;

/// The register spans a request reads and writes (holding / input registers only:
/// the coil table of the R6, FC01/05/0F, holds no sequence).
struct Access {
    std::uint32_t read_address = 0;
    std::uint32_t read_count = 0;
    std::uint32_t write_address = 0;
    std::uint32_t write_count = 0;
};

Access access_of(const protocol::Request& request) {
    Access a;
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

/// A select-then-read indirection: a write to @p select begins it, a read of
/// @p block finishes it. FC17 that selects and reads in one request is complete in
/// itself: it only has to wait for another client's sequence to end (use).
Role indirection_role(const Access& a, r6::Span select, r6::Span block) {
    const bool selects = select.overlaps(a.write_address, a.write_count);
    const bool reads = block.overlaps(a.read_address, a.read_count);
    if (selects && reads) return Role::use;
    if (selects) return Role::begin;
    if (reads) return Role::finish;
    if (block.overlaps(a.write_address, a.write_count)) return Role::use;
    return Role::none;
}

/// The upload has no closing request (seed 004 3.3.5: any number of frames may
/// follow the set-up): set-up begins, everything else in the block uses.
Role upload_role(const Access& a) {
    if (r6::source_edit_setup.overlaps(a.write_address, a.write_count)) return Role::begin;
    if (r6::source_edit_block.overlaps(a.write_address, a.write_count) ||
        r6::source_edit_block.overlaps(a.read_address, a.read_count)) {
        return Role::use;
    }
    return Role::none;
}

bool is_urgent(const Access& a) {
    for (const std::uint16_t stop : {r6::command_stop, r6::command_pause, r6::command_stop_button}) {
        if (a.write_count > 0 && a.write_address <= stop && stop < a.write_address + a.write_count) {
            return true;
        }
    }
    return false;
}

}  // namespace

const char* to_string(Resource resource) noexcept {
    switch (resource) {
        case Resource::counter_read: return "counter read (0x0883-0x0888)";
        case Resource::source_view: return "data-source view (0x7530-0x7531)";
        case Resource::source_upload: return "data-source upload (0x7532-0x9C40)";
    }
    return "unknown resource";
}

bool RequestClass::touches_any() const noexcept {
    for (const Role r : roles) {
        if (r != Role::none) return true;
    }
    return false;
}

Classified classify(protocol::ByteView pdu) {
    Classified out;
    if (pdu.empty() || pdu[0] == 0 || pdu[0] >= protocol::fc::exception_flag) {
        out.local.code = ExceptionCode::illegal_function;
        return out;
    }
    const auto decoded = protocol::decode_request(pdu);
    if (!decoded.complete()) {
        // Modbus Application Protocol V1.1b3 6.x: a quantity or byte count the
        // function cannot carry is exception 03.
        out.local.code = ExceptionCode::illegal_data_value;
        return out;
    }
    RequestClass c;
    c.priority = protocol::is_write(pdu[0]) ? engine::Priority::command : engine::Priority::on_demand;
    const Access a = access_of(decoded.value);
    c.urgent = is_urgent(a);
    c.roles[static_cast<std::size_t>(Resource::counter_read)] =
        indirection_role(a, r6::counter_select, r6::counter_block);
    c.roles[static_cast<std::size_t>(Resource::source_view)] =
        indirection_role(a, r6::source_view_select, r6::source_view_block);
    c.roles[static_cast<std::size_t>(Resource::source_upload)] = upload_role(a);
    out.request = c;
    return out;
}

}  // namespace fieldbridge::northbound::upstream
