#include "northbound/mqtt/r6_source.hpp"

#include <map>
#include <vector>
#include <utility>

#include <asio/post.hpp>

#include "core/error.hpp"
#include "core/modbus_ids.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "northbound/upstream/r6_operations.hpp"

namespace fieldbridge::northbound::mqtt {

namespace {

/// MQTT commands reach the target as the requests of one pseudo client: the upstream
/// keeps stateful sequences per connection, and this one never starts any.
constexpr std::uint64_t mqtt_connection = 0xFFFF'FFFF'FFFF'FF00ULL;

/// Shared by the sources of one target: the target's one state callback fans out.
struct Hub {
    upstream::UpstreamTarget* target = nullptr;
    /// Several per unit: one source per consumer (the JSON bridge, the Sparkplug node).
    std::multimap<core::UnitId, std::shared_ptr<SourceListener>> listeners;
};

class R6Source final : public DeviceSource {
public:
    R6Source(asio::io_context& io, std::shared_ptr<Hub> hub, const config::UpstreamUnitConfig& unit)
        : io_(io), hub_(std::move(hub)), unit_(unit.unit_id), name_(unit.name),
          listener_(std::make_shared<SourceListener>()) {
        hub_->listeners.emplace(unit_, listener_);
    }
    ~R6Source() override {
        const auto [first, last] = hub_->listeners.equal_range(unit_);
        for (auto it = first; it != last; ++it) {
            if (it->second == listener_) {
                hub_->listeners.erase(it);
                break;
            }
        }
    }

    const std::string& name() const override { return name_; }
    std::string_view type() const override { return "r6"; }
    engine::OperationSet operations() const override { return r6::r6_operations(); }
    bool commands_enabled() const override { return true; }

    SourceState state() const override {
        SourceState s;
        s.quality = engine::Quality::offline;
        if (hub_->target == nullptr) return s;
        const auto state = hub_->target->state(unit_);
        if (!state) return s;
        s.online = state->online;
        s.decoded = state->state;
        if (state->updated != engine::TimePoint{}) s.updated = state->updated;
        if (const engine::RegisterImage* image = hub_->target->image(unit_)) {
            for (const engine::RegisterEntry& e : image->entries(engine::Table::holding)) {
                if (e.quality != engine::Quality::unknown) s.raw.push_back({engine::Table::holding, e.address, e.value});
            }
        }
        if (!s.online) {
            s.quality = engine::Quality::offline;
        } else {
            s.quality = s.decoded.fields.empty() ? engine::Quality::unknown : engine::Quality::good;
        }
        return s;
    }

    std::vector<engine::Alarm> alarms() const override {
        if (hub_->target == nullptr) return {};
        const auto state = hub_->target->state(unit_);
        return state ? state->alarms : std::vector<engine::Alarm>{};
    }

    void set_listener(SourceListener listener) override { *listener_ = std::move(listener); }

    /// The target is going away (shared by every unit of the target).
    void detach() noexcept { hub_->target = nullptr; }

    std::optional<protocol::ExceptionCode> validate(const protocol::Request& request) const override {
        if (hub_->target == nullptr) return protocol::exception_code(protocol::GatewayRefusal::path_down);
        try {
            (void)protocol::encode_request(request);
        } catch (const core::InvalidArgument&) {
            return protocol::exception_code(protocol::GatewayRefusal::bad_value);
        }
        return std::nullopt;
    }

    void execute(const protocol::Request& request, engine::ResponseHandler done) override {
        const core::FunctionCode function = protocol::function_code(request);
        if (hub_->target == nullptr) {
            asio::post(io_, [done = std::move(done), function] {
                done(protocol::exception_response(function, protocol::GatewayRefusal::path_down));
            });
            return;
        }
        const protocol::Bytes pdu = protocol::encode_request(request);
        hub_->target->handle(unit_, pdu, ClientRef{mqtt_connection, {}},
                             [done = std::move(done), request, function](protocol::Bytes reply) {
                                 const auto decoded = protocol::decode_response(reply, request);
                                 if (decoded.complete()) {
                                     done(decoded.value);
                                 } else {
                                     // A reply that does not answer the request.
                                     done(protocol::exception_response(function,
                                                                       protocol::GatewayRefusal::gateway_failure));
                                 }
                             });
    }

private:
    asio::io_context& io_;
    std::shared_ptr<Hub> hub_;
    core::UnitId unit_;
    std::string name_;
    std::shared_ptr<SourceListener> listener_;
};

}  // namespace

std::vector<std::shared_ptr<DeviceSource>> make_r6_sources(asio::io_context& io, upstream::UpstreamTarget& target,
                                                           std::size_t copies) {
    auto hub = std::make_shared<Hub>();
    hub->target = &target;
    target.set_state_callback([weak = std::weak_ptr<Hub>(hub)](const upstream::R6State& state) {
        const auto h = weak.lock();
        if (!h) return;
        // Copied: a listener may replace itself or go.
        std::vector<std::shared_ptr<SourceListener>> listeners;
        const auto [first, last] = h->listeners.equal_range(state.unit_id);
        for (auto it = first; it != last; ++it) listeners.push_back(it->second);
        for (const auto& listener : listeners) {
            if (listener->changed) listener->changed();
        }
    });
    std::vector<std::shared_ptr<DeviceSource>> sources;
    for (std::size_t copy = 0; copy < copies; ++copy) {
        for (const config::UpstreamUnitConfig& unit : target.config().units) {
            sources.push_back(std::make_shared<R6Source>(io, hub, unit));
        }
    }
    return sources;
}

void detach_r6_sources(const std::vector<std::shared_ptr<DeviceSource>>& sources) {
    for (const auto& source : sources) {
        if (auto* r6 = dynamic_cast<R6Source*>(source.get())) r6->detach();
    }
}

}  // namespace fieldbridge::northbound::mqtt
