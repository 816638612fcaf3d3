#pragma once
/// @file process_cpu.hpp
/// The CPU time this process has used so far, user and kernel apart
/// (getrusage(RUSAGE_SELF)): what the line benchmark and its floor divide by their
/// transactions.
#include <sys/resource.h>

namespace fieldbridge::bench {

struct CpuTimes {
    double user = 0.0;  ///< seconds
    double sys = 0.0;   ///< seconds
};

inline CpuTimes process_cpu() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const auto seconds = [](const timeval& tv) {
        return static_cast<double>(tv.tv_sec) + static_cast<double>(tv.tv_usec) / 1e6;
    };
    return {seconds(usage.ru_utime), seconds(usage.ru_stime)};
}

}  // namespace fieldbridge::bench
