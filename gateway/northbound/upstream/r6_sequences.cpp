#include "northbound/upstream/r6_sequences.hpp"

#include <fmt/format.h>

#include "northbound/upstream/r6_map.hpp"

namespace fieldbridge::northbound::upstream {
namespace {

/// The registers of one sequence: @p select begins it, @p block is all it covers.
struct Sequence {
    const char* name;
    r6::Span select;
    r6::Span block;
};

Sequence sequence_of(Resource resource) noexcept {
    switch (resource) {
        case Resource::counter_read: return {"counter read", r6::counter_select, r6::counter_block};
        case Resource::source_view: return {"data-source view", r6::source_view_select, r6::source_view_block};
        case Resource::source_upload: break;
    }
    return {"data-source upload", r6::source_edit_setup, r6::source_edit_block};
}

Role indirection_role(const RegisterAccess& a, const Sequence& s) noexcept {
    const bool selects = s.select.overlaps(a.write_address, a.write_count);
    const bool reads = s.block.overlaps(a.read_address, a.read_count);
    if (selects && reads) return Role::use;
    if (selects) return Role::begin;
    if (reads) return Role::finish;
    if (s.block.overlaps(a.write_address, a.write_count)) return Role::use;
    return Role::none;
}

Role upload_role(const RegisterAccess& a, const Sequence& s) noexcept {
    if (s.select.overlaps(a.write_address, a.write_count)) return Role::begin;
    if (s.block.overlaps(a.write_address, a.write_count) || s.block.overlaps(a.read_address, a.read_count)) {
        return Role::use;
    }
    return Role::none;
}

}  // namespace

std::string to_string(Resource resource) {
    const Sequence s = sequence_of(resource);
    return fmt::format("{} (0x{:04X}-0x{:04X})", s.name, s.block.first, s.block.last);
}

Role role_in(Resource resource, const RegisterAccess& access) noexcept {
    const Sequence s = sequence_of(resource);
    return resource == Resource::source_upload ? upload_role(access, s) : indirection_role(access, s);
}

bool writes_stop(const RegisterAccess& access) noexcept {
    for (const std::uint16_t stop : {r6::command_stop, r6::command_pause, r6::command_stop_button}) {
        if (access.write_count > 0 && access.write_address <= stop &&
            stop < access.write_address + access.write_count) {
            return true;
        }
    }
    return false;
}

}  // namespace fieldbridge::northbound::upstream
