#include "northbound/modbus_tcp/unit_router.hpp"

#include <algorithm>

namespace fieldbridge::northbound::modbus_tcp {

std::size_t UnitRouter::size() const noexcept {
    return static_cast<std::size_t>(std::count_if(targets_.begin(), targets_.end(), [](const UnitTarget* t) { return t != nullptr; }));
}

std::vector<UnitTarget*> UnitRouter::targets() const {
    std::vector<UnitTarget*> out;
    for (UnitTarget* target : targets_) {
        if (target != nullptr && std::find(out.begin(), out.end(), target) == out.end()) out.push_back(target);
    }
    return out;
}

}  // namespace fieldbridge::northbound::modbus_tcp
