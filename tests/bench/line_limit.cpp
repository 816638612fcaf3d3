#include "line_limit.hpp"

#include "engine/line_timing.hpp"

namespace fieldbridge::bench {

LineLimit line_limit(const LoadShape& shape, std::uint32_t baud, std::chrono::nanoseconds turnaround) {
    using Ms = std::chrono::duration<double, std::milli>;
    const engine::LineTiming timing(engine::CharacterFormat{baud, 8, false, 1});
    const auto turn = std::chrono::duration_cast<engine::Duration>(turnaround);
    LineLimit limit;
    limit.baud = baud;
    limit.t_read_ms =
        Ms(timing.transaction_time(LoadShape::read_request_bytes(), LoadShape::read_reply_bytes(), turn)).count();
    limit.t_write_ms =
        Ms(timing.transaction_time(shape.write_request_bytes(), shape.write_reply_bytes(), turn)).count();
    limit.t3_5_us = std::chrono::duration<double, std::micro>(timing.t3_5()).count();
    limit.limit_tps = 1000.0 / limit.t_read_ms;
    return limit;
}

}  // namespace fieldbridge::bench
