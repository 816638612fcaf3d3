#include "app/device_sources.hpp"

namespace fieldbridge::app {

std::vector<DeviceSources::Source> DeviceSources::rebuild(engine::Engine* engine) {
    detach();
    std::vector<Source> sources;
    if (engine != nullptr) {
        for (const engine::DeviceEntry& entry : engine->devices()) {
            auto source = std::make_shared<northbound::mqtt::AgentSource>(io_, *entry.agent, entry.mqtt_commands, notices_);
            own_.push_back(source);
            sources.push_back(std::move(source));
        }
    }
    for (const Provider& provider : providers_) {
        for (Source& source : provider()) sources.push_back(std::move(source));
    }
    return sources;
}

void DeviceSources::detach() {
    for (const auto& source : own_) source->detach();
    own_.clear();
}

}  // namespace fieldbridge::app
