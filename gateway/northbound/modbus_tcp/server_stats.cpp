#include "northbound/modbus_tcp/server_stats.hpp"

#include <numeric>

namespace fieldbridge::northbound::modbus_tcp {

std::uint64_t ServerStats::exceptions_total() const noexcept {
    return std::accumulate(exceptions_by_code.begin(), exceptions_by_code.end(), std::uint64_t{0});
}

std::string ServerStats::summary() const {
    return "Modbus TCP: " + std::to_string(connections_open) + " client(s), " + std::to_string(requests) +
           " request(s), " + std::to_string(exceptions_total()) + " exception(s), " +
           std::to_string(closed_malformed) + " closed malformed";
}

}  // namespace fieldbridge::northbound::modbus_tcp
