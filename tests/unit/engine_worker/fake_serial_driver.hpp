#pragma once
// A serial driver's TIOCGSERIAL / TIOCSSERIAL played by the test: the low-latency
// request against drivers that take the flag, refuse it, drop it or lack the call.
#include <linux/serial.h>

#include <vector>

#include "engine/serial_low_latency.hpp"

namespace worker_test {

namespace fe = fieldbridge::engine;

/// A driver's serial_struct and what the test wants its ioctls to do.
struct FakeDriver {
    int flags = 0;
    int get_error = 0;
    int set_error = 0;
    bool drops_flag = false;
    std::vector<int> set_flags;  ///< the flags of each TIOCSSERIAL

    fe::SerialIoctls ioctls() {
        return fe::SerialIoctls{
            [this](int, serial_struct& out) {
                if (get_error != 0) return get_error;
                out.flags = flags;
                return 0;
            },
            [this](int, const serial_struct& in) {
                set_flags.push_back(in.flags);
                if (set_error != 0) return set_error;
                flags = drops_flag ? (in.flags & ~ASYNC_LOW_LATENCY) : in.flags;
                return 0;
            },
        };
    }
};

}  // namespace worker_test
