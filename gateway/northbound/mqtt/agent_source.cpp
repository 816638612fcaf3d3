#include "northbound/mqtt/agent_source.hpp"

#include <algorithm>

#include <asio/post.hpp>

#include "engine/profiles/modbus_profile.hpp"
#include "protocol/gateway_exceptions.hpp"

namespace fieldbridge::northbound::mqtt {

SourceState image_state(const engine::DeviceProfile& profile, const engine::RegisterImage& image, bool online) {
    SourceState s;
    s.online = online && !image.offline();
    bool any = false;
    bool stale = false;
    for (std::size_t t = 0; t < engine::table_count; ++t) {
        const auto table = static_cast<engine::Table>(t);
        for (const engine::RegisterEntry& e : image.entries(table)) {
            if (e.quality == engine::Quality::unknown) continue;
            any = true;
            stale = stale || e.quality != engine::Quality::good;
            if (!s.updated || e.updated > *s.updated) s.updated = e.updated;
            s.raw.push_back(RawRegister{table, e.address, e.value});
        }
    }
    if (!s.online) {
        s.quality = engine::Quality::offline;
    } else if (!any) {
        s.quality = engine::Quality::unknown;
    } else {
        s.quality = stale ? engine::Quality::stale : engine::Quality::good;
    }
    s.decoded = profile.decode_state(image);
    return s;
}

AgentSource::AgentSource(asio::io_context& io, engine::DeviceAgent& agent, bool commands_enabled, bool notices)
    : io_(io),
      agent_(&agent),
      name_(agent.config().name),
      type_(agent.config().type_name.empty() ? std::string{engine::to_string(agent.profile().type())}
                                              : agent.config().type_name),
      operations_(agent.profile().operations()),
      commands_enabled_(commands_enabled),
      notices_(notices),
      listener_(std::make_shared<SourceListener>()) {
    if (const auto* modbus = dynamic_cast<const engine::ModbusProfile*>(&agent.profile())) {
        points_ = modbus->options().points;
    }
    const std::weak_ptr<SourceListener> weak = listener_;
    subscription_ = agent.image().subscribe([weak](const engine::ImageChange&) {
        if (auto l = weak.lock(); l && l->changed) l->changed();
    });
    if (notices_) {
        agent.set_notice_callback([weak](const engine::DeviceNotice& notice) {
            if (auto l = weak.lock(); l && l->notice) l->notice(notice);
        });
    }
}

AgentSource::~AgentSource() {
    if (agent_ != nullptr) {
        (void)agent_->image().unsubscribe(subscription_);
        if (notices_) agent_->set_notice_callback({});
    }
}

void AgentSource::detach() noexcept {
    agent_ = nullptr;
    *listener_ = SourceListener{};
}

std::string_view AgentSource::type() const { return type_; }

SourceState AgentSource::state() const {
    if (agent_ == nullptr) {
        SourceState s;
        s.quality = engine::Quality::offline;
        return s;
    }
    return image_state(agent_->profile(), agent_->image(), agent_->online());
}

engine::DecodedState AgentSource::shape() const {
    if (agent_ == nullptr) return {};
    // The built-in types' registers all lie in the first 8192 of each table
    // (docs/registers.md); a device with points has its fields from its points.
    constexpr std::size_t span = 8192;
    std::vector<std::uint16_t> words(span);
    std::vector<std::uint16_t> bits(span);
    for (std::size_t i = 0; i < span; ++i) {
        words[i] = static_cast<std::uint16_t>((i * 37 + 11) % 1000);
        bits[i] = static_cast<std::uint16_t>(i % 2);
    }
    engine::RegisterImage image;
    const engine::TimePoint now = engine::Clock::now();
    image.update(engine::Table::holding, 0, words, now);
    image.update(engine::Table::input, 0, words, now);
    image.update(engine::Table::coils, 0, bits, now);
    image.update(engine::Table::discrete_inputs, 0, bits, now);
    return image_state(agent_->profile(), image, true).decoded;
}

std::vector<engine::Alarm> AgentSource::alarms() const {
    if (agent_ == nullptr) return {};
    return agent_->profile().alarms(agent_->image());
}

void AgentSource::set_listener(SourceListener listener) {
    if (agent_ == nullptr) return;
    *listener_ = std::move(listener);
}

std::optional<protocol::ExceptionCode> AgentSource::validate(const protocol::Request& request) const {
    if (agent_ == nullptr) return protocol::exception_code(protocol::GatewayRefusal::path_down);
    return agent_->profile().validate(request, agent_->image());
}

void AgentSource::execute(const protocol::Request& request, engine::ResponseHandler done) {
    if (agent_ == nullptr) {
        const core::FunctionCode function = protocol::function_code(request);
        asio::post(io_, [done = std::move(done), function] {
            done(protocol::Response{protocol::exception_response(function, protocol::GatewayRefusal::path_down)});
        });
        return;
    }
    agent_->request(request, std::move(done));
}

}  // namespace fieldbridge::northbound::mqtt
