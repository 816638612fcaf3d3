#pragma once
/// @file sim_error.hpp
/// The one exception type of the simulator runtime: start-up, option and resource
/// errors (a pty that cannot be opened, a bad --bus spec, a port in use). what()
/// says what failed, where, and what to do. Per-frame outcomes are counters, never
/// exceptions.

#include <stdexcept>

namespace fieldbridge::sim::runtime {

class SimError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace fieldbridge::sim::runtime
