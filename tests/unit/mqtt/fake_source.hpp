#pragma once
// A DeviceSource driven by the test: its state, alarms and the answers to commands.
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/post.hpp>

#include "engine/profiles/wtec_common.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "northbound/mqtt/device_source.hpp"

namespace fbt {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
namespace fp = fieldbridge::protocol;

class FakeSource final : public fm::DeviceSource {
public:
    FakeSource(asio::io_context& io, std::string name, fe::OperationSet operations = fe::xeg_operations())
        : io_(io), name_(std::move(name)), operations_(operations) {
        state_.online = true;
        state_.quality = fe::Quality::good;
        state_.updated = fe::Clock::now();
        set_position(10.0);
    }

    const std::string& name() const override { return name_; }
    std::string_view type() const override { return "hiwin-xeg"; }
    fe::OperationSet operations() const override { return operations_; }
    bool commands_enabled() const override { return commands_enabled_; }
    fm::SourceState state() const override { return state_; }
    fe::DecodedState shape() const override { return shape_ ? *shape_ : state_.decoded; }
    std::vector<fe::Alarm> alarms() const override { return alarms_; }
    void set_listener(fm::SourceListener listener) override { listener_ = std::move(listener); }
    std::optional<fp::ExceptionCode> validate(const fp::Request& request) const override {
        // As the XEG profile: positions beyond 64 mm are out of range.
        if (const auto* w = std::get_if<fp::WriteMultipleRegistersRequest>(&request);
            w != nullptr && w->address == 0x0630 && !w->values.empty() && w->values[0] > 6400) {
            return fp::ExceptionCode::illegal_data_value;
        }
        return std::nullopt;
    }
    void execute(const fp::Request& request, fe::ResponseHandler done) override {
        executed.push_back(request);
        fp::Response response = fp::WriteSingleResponse{fp::fc::write_single_register, 0, 0};
        if (!answers.empty()) {
            response = answers.front();
            answers.pop_front();
        }
        asio::post(io_, [done = std::move(done), response] { done(response); });
    }

    // ---- test controls ----
    void set_position(double mm) {
        state_.decoded.fields = {fe::Field{"status", std::string("positioned"), ""},
                                 fe::Field{"position_mm", mm, "mm"}};
        state_.raw = {fm::RawRegister{fe::Table::input, 0x0300, static_cast<std::uint16_t>(mm * 100)}};
        state_.updated = fe::Clock::now();
        changed();
    }
    /// Replaces the decoded fields (another device type's state).
    void set_fields(std::vector<fe::Field> fields) {
        state_.decoded.fields = std::move(fields);
        changed();
    }
    /// Adds a register to the raw image (e.g. a WTEC's init direction, holding 0x0300).
    void add_register(fm::RawRegister r) {
        state_.raw.push_back(r);
        changed();
    }
    void set_online(bool online) {
        state_.online = online;
        state_.quality = online ? fe::Quality::good : fe::Quality::offline;
        changed();
    }
    void set_alarms(std::vector<fe::Alarm> alarms) {
        alarms_ = std::move(alarms);
        changed();
    }
    void changed() {
        if (listener_.changed) listener_.changed();
    }

    std::optional<fe::DecodedState> shape_;  ///< what shape() says; default: the state's fields
    std::vector<fp::Request> executed;
    std::deque<fp::Response> answers;  ///< next answers to execute(); default: a write echo
    bool commands_enabled_ = true;

private:
    asio::io_context& io_;
    std::string name_;
    fe::OperationSet operations_;
    fm::SourceState state_;
    std::vector<fe::Alarm> alarms_;
    fm::SourceListener listener_;
};

}  // namespace fbt
