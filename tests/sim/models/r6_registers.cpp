// The R6 register map (seed 004 section 4 "地址表定义"): which address starts which
// element, how wide it is, what it reads, what a write must look like.
#include "models/r6_model.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;

constexpr std::uint16_t version_length = 0x0000;
constexpr std::uint16_t version_first = 0x0001;
constexpr std::uint16_t version_last = 0x0040;
constexpr std::uint16_t counter_count = 0x0082;
constexpr std::uint16_t counter_list = 0x0083;
constexpr std::uint16_t counter_list_end = 0x0883;  // 1024 IDs of 2 registers
constexpr std::uint16_t counter_select = 0x0883;
constexpr std::uint16_t counter_target = 0x0885;
constexpr std::uint16_t counter_current = 0x0887;
constexpr std::uint16_t mode = 0x0889;
constexpr std::uint16_t io_board_count = 0x088A;
constexpr std::uint16_t inputs_first = 0x088B;
constexpr std::uint16_t outputs_first = 0x08B3;
constexpr std::uint16_t axis_count = 0x08DB;
constexpr std::uint16_t axes_first = 0x08DC;
constexpr std::uint16_t world_first = 0x091C;
constexpr std::uint16_t alarm_number = 0x095C;
constexpr std::uint16_t cycle_current = 0x095D;
constexpr std::uint16_t cycle_last = 0x0961;
constexpr std::uint16_t host_address = 0x0965;
constexpr std::uint16_t torque_first = 0x0966;
constexpr std::uint16_t speed_first = 0x0986;
constexpr std::uint16_t move_state = 0x09A6;
constexpr std::uint16_t origin_state = 0x09A7;
constexpr std::uint16_t counter_modify = 0x4E52;
constexpr std::uint16_t single_output = 0x4E58;
constexpr std::uint16_t global_speed = 0x4EE8;
constexpr std::uint16_t parameters_first = 0x4F4C;
constexpr std::uint16_t view_source = 0x7530;
constexpr std::uint16_t view_points = 0x7531;
constexpr std::uint16_t edit_source = 0x7532;
constexpr std::uint16_t edit_format = 0x7533;
constexpr std::uint16_t edit_mask = 0x7534;
constexpr std::uint16_t upload = 0x7535;
constexpr std::uint16_t upload_clear = 0x7536;
constexpr std::uint16_t max_global_speed = 1000;
constexpr std::size_t io_board_slots = 5;
constexpr std::int32_t rated_torque = 2580;  // seed 004 3.1.13: 2580 is one rated torque

std::vector<std::uint16_t> pair(std::uint32_t value) {
    return {static_cast<std::uint16_t>(value >> 16), static_cast<std::uint16_t>(value & 0xFFFF)};
}

std::vector<std::uint16_t> quad(std::uint64_t value) {
    return {static_cast<std::uint16_t>(value >> 48), static_cast<std::uint16_t>((value >> 32) & 0xFFFF),
            static_cast<std::uint16_t>((value >> 16) & 0xFFFF), static_cast<std::uint16_t>(value & 0xFFFF)};
}

std::uint32_t join(const std::vector<std::uint16_t>& words, std::size_t at) {
    return (static_cast<std::uint32_t>(words[at]) << 16) | words[at + 1];
}

/// The board whose 2-register block starts at @p address in a board area, if any.
std::optional<std::size_t> board_at(std::uint16_t address, std::uint16_t first) {
    if (address < first || (address - first) % 2 != 0) return std::nullopt;
    const std::size_t board = (address - first) / 2;
    if (board >= R6Model::board_count) return std::nullopt;
    return board;
}

}  // namespace

bool R6Model::board_exists(std::size_t board) const noexcept {
    // seed 004 3.1.6: valid board addresses depend on the IO board count; the M and
    // EU blocks are always there.
    return board >= io_board_slots ? board < board_count : board < io_boards_;
}

std::optional<std::vector<std::uint16_t>> R6Model::read_element(std::uint16_t a) const {
    using Words = std::vector<std::uint16_t>;
    // seed 004 3.1.1: the length 0x29 counts the 40 characters and their terminating NUL.
    if (a == version_length) return Words{static_cast<std::uint16_t>(version_.size() + 1)};
    if (a >= version_first && a <= version_last) {
        // seed 004 3.1.2: two characters a register, the last one padded with 0.
        const std::size_t at = static_cast<std::size_t>(a - version_first) * 2;
        const auto byte = [&](std::size_t i) -> std::uint16_t {
            return i < version_.size() ? static_cast<std::uint8_t>(version_[i]) : 0;
        };
        return Words{static_cast<std::uint16_t>((byte(at) << 8) | byte(at + 1))};
    }
    if (a == counter_count) return Words{static_cast<std::uint16_t>(counters_.size())};
    if (a >= counter_list && a < counter_list_end) {
        if ((a - counter_list) % 2 != 0) return std::nullopt;
        // seed 004 3.1.3: past the last counter the reply is padded with 0xFF.
        const std::size_t k = (a - counter_list) / 2;
        return k < counters_.size() ? pair(counters_[k].id) : Words{0xFFFF, 0xFFFF};
    }
    const Counter* selected = find_counter(selected_counter_);
    if (a == counter_select) return pair(selected_counter_);
    if (a == counter_target) return pair(selected ? selected->target : 0);
    if (a == counter_current) return pair(selected ? selected->current : 0);
    if (a == mode) return Words{mode_};
    if (a == io_board_count) return Words{io_boards_};
    if (const auto board = board_at(a, inputs_first); board && board_exists(*board)) {
        return pair(inputs_[*board]);
    }
    if (const auto board = board_at(a, outputs_first); board && board_exists(*board)) {
        return pair(outputs_[*board]);
    }
    if (a == axis_count) return Words{axis_count_};
    if (a >= axes_first && a < axes_first + 2 * max_axes && (a - axes_first) % 2 == 0) {
        const std::size_t axis = (a - axes_first) / 2;
        if (axis >= axis_count_) return std::nullopt;
        return pair(static_cast<std::uint32_t>(axes_[axis]));
    }
    if (a >= world_first && a < world_first + 2 * max_axes && (a - world_first) % 2 == 0) {
        const std::size_t axis = (a - world_first) / 2;
        return pair(static_cast<std::uint32_t>(axis < axis_count_ ? axes_[axis] : 0));
    }
    if (a == alarm_number) return Words{alarm_};
    if (a == cycle_current) return quad(cycle_ms_);
    if (a == cycle_last) return quad(last_cycle_ms_);
    if (a == host_address) return Words{host_address_};
    if (a >= torque_first && a < torque_first + max_axes) {
        const std::size_t axis = a - torque_first;
        const bool active = moving_ && axis < axis_count_;
        return Words{static_cast<std::uint16_t>(active ? rated_torque * 3 / 10 + 20 * static_cast<std::int32_t>(axis) : 0)};
    }
    if (a >= speed_first && a < speed_first + max_axes) {
        const std::size_t axis = a - speed_first;
        // Motor rpm of the sweep (joint deg/s x a 50:1 gear / 6).
        const std::int64_t joint_mdeg_s = std::int64_t{10'000} * global_speed_ / max_global_speed *
                                          (30 + 10 * static_cast<std::int64_t>(axis)) / 30;
        const bool active = moving_ && axis < axis_count_;
        return Words{static_cast<std::uint16_t>(active ? joint_mdeg_s * 50 / 6000 : 0)};
    }
    if (a == move_state) return Words{static_cast<std::uint16_t>(moving_ ? 1 : 0)};
    if (a == origin_state) return Words{static_cast<std::uint16_t>(origin_set_ ? 1 : 0)};
    if (a == global_speed) return Words{global_speed_};
    if (a >= parameters_first && a < parameters_first + 2 * parameter_count) {
        if ((a - parameters_first) % 2 != 0) return std::nullopt;
        return pair(static_cast<std::uint32_t>(parameters_[(a - parameters_first) / 2]));
    }
    if (a == view_source) return Words{view_source_};
    if (a == view_points) {
        const auto it = sources_.find(view_source_);
        const std::uint32_t points = it == sources_.end() ? 0 : it->second.points;
        return Words{static_cast<std::uint16_t>(points > 0xFFFF ? 0xFFFF : points)};
    }
    if (a == edit_source) return Words{edit_source_};
    if (a == edit_format) return Words{edit_format_};
    if (a == edit_mask) return Words{edit_mask_};
    if (a == upload) return Words{upload_points_};
    if (a == upload_clear) return Words{upload_clear_};
    return std::nullopt;
}

std::size_t R6Model::writable_width(std::uint16_t a, std::size_t remaining) const {
    if (a == counter_select) return 2;
    if (const auto board = board_at(a, outputs_first); board && board_exists(*board)) return 2;
    if (a == counter_modify) return 6;
    if (a == single_output) return 3;
    if (a == global_speed || a == view_source || a == edit_source || a == edit_format ||
        a == edit_mask || a == upload_clear) {
        return 1;
    }
    if (a >= parameters_first && a < parameters_first + 2 * parameter_count &&
        (a - parameters_first) % 2 == 0) {
        return 2;
    }
    // seed 004 3.3.5: an upload frame is the point count, the clear flag and the points.
    if (a == upload) return remaining >= 2 ? remaining : 0;
    return 0;
}

std::optional<protocol::ExceptionCode> R6Model::check_write(const ElementWrite& w) const {
    const auto& v = w.words;
    const auto bad = std::optional{ExceptionCode::illegal_data_value};
    switch (w.address) {
        case counter_select: return find_counter(join(v, 0)) ? std::nullopt : bad;
        case counter_modify: return find_counter(join(v, 0)) ? std::nullopt : bad;
        case single_output: {
            // 4E58 board 0-8 (IO 0-4, M 5-7, EU 8), 4E59 point 0-31, 4E5A state 0-1.
            if (v[0] >= board_count || !board_exists(v[0]) || v[1] > 31 || v[2] > 1) return bad;
            return std::nullopt;
        }
        case global_speed: return v[0] <= max_global_speed ? std::nullopt : bad;
        case edit_format: return (v[0] == 4 || v[0] == 6) ? std::nullopt : bad;
        case edit_mask: return v[0] <= 0x3F ? std::nullopt : bad;
        case upload_clear: return v[0] <= 1 ? std::nullopt : bad;
        case upload: {
            if (v[1] > 1) return bad;
            const std::size_t expected = std::size_t{v[0]} * edit_format_ * 2;
            return v.size() - 2 == expected ? std::nullopt : bad;
        }
        default: return std::nullopt;
    }
}

void R6Model::apply_write(const ElementWrite& w) {
    const auto& v = w.words;
    if (w.address == counter_select) {
        selected_counter_ = join(v, 0);
    } else if (w.address == counter_modify) {
        // seed 004 3.3.2: the host may not change the target; only the current value.
        find_counter(join(v, 0))->current = join(v, 4);
    } else if (w.address == single_output) {
        const std::uint32_t bit = std::uint32_t{1} << v[1];
        outputs_[v[0]] = v[2] != 0 ? (outputs_[v[0]] | bit) : (outputs_[v[0]] & ~bit);
    } else if (w.address == global_speed) {
        global_speed_ = v[0];
    } else if (w.address == view_source) {
        view_source_ = v[0];
    } else if (w.address == edit_source) {
        edit_source_ = v[0];
    } else if (w.address == edit_format) {
        edit_format_ = v[0];
    } else if (w.address == edit_mask) {
        edit_mask_ = v[0];
    } else if (w.address == upload_clear) {
        upload_clear_ = v[0];
        if (v[0] == 1) sources_[edit_source_] = DataSource{};
    } else if (w.address == upload) {
        upload_points_ = v[0];
        upload_clear_ = v[1];
        DataSource& source = sources_[edit_source_];
        if (v[1] == 1) source = DataSource{};
        for (std::size_t i = 2; i + 1 < v.size(); i += 2) {
            source.values.push_back(static_cast<std::int32_t>(join(v, i)));
        }
        source.points += v[0];
    } else if (const auto board = board_at(w.address, outputs_first)) {
        outputs_[*board] = join(v, 0);
    } else {
        parameters_[(w.address - parameters_first) / 2] = static_cast<std::int32_t>(join(v, 0));
    }
}

}  // namespace fieldbridge::sim
