#include "scan/device_probe.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <variant>

#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/profile_text.hpp"
#include "engine/profiles/wtec_rtu_profile.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace fieldbridge::scan {

namespace {

/// Any Modbus device: the first holding register. Which registers tell the device
/// types apart is their profiles' knowledge (`*_identification()`).
constexpr engine::IdentificationRead presence{0, 1};

[[nodiscard]] protocol::Request read_of(const core::IdentifyRead& read) {
    return protocol::ReadRegistersRequest{read.table == core::RegisterTable::input ? protocol::fc::read_input_registers
                                                                                   : protocol::fc::read_holding_registers,
                                          read.address, read.count};
}

[[nodiscard]] protocol::Request read_holding(engine::IdentificationRead read) {
    return protocol::ReadRegistersRequest{protocol::fc::read_holding_registers, read.address, read.count};
}

/// The register, or the first and last ones ("A-B") for a read of several.
[[nodiscard]] std::string span_text(engine::IdentificationRead read) {
    std::string text = engine::hex_word(read.address);
    if (read.count > 1) text += "-" + engine::hex_word(static_cast<std::uint16_t>(read.address + read.count - 1));
    return text;
}

/// The values of a register read reply; nullopt for an exception or nothing.
[[nodiscard]] std::optional<std::vector<std::uint16_t>> values_of(const std::optional<protocol::Response>& reply) {
    if (!reply) {
        return std::nullopt;
    }
    const auto* read = std::get_if<protocol::ReadRegistersResponse>(&*reply);
    if (read == nullptr) {
        return std::nullopt;
    }
    return read->values;
}

}  // namespace

ModbusProbe::ModbusProbe(std::uint8_t address, std::vector<DefinitionIdentify> definitions)
    : address_(address), definitions_(std::move(definitions)) {}

std::optional<protocol::Request> ModbusProbe::next() const {
    switch (step_) {
        case Step::presence: return read_holding(presence);
        case Step::xeg_model: return read_holding(engine::xeg_identification());
        case Step::wtec_id: return read_holding(engine::wtec_rtu_identification());
        case Step::excd_version: return read_holding(engine::excd_identification());
        case Step::definitions: return read_of(definitions_[definition_].read);
        case Step::finished: break;
    }
    return std::nullopt;
}

void ModbusProbe::identified(engine::DeviceType type, std::string detail) {
    found_ = FoundDevice{address_, type, std::move(detail), holding_zero_readable_, {}};
    step_ = Step::finished;
}

void ModbusProbe::try_definitions(std::size_t from) {
    if (from < definitions_.size()) {
        definition_ = from;
        step_ = Step::definitions;
        return;
    }
    identified(engine::DeviceType::modbus,
               "answers FC03 at " + span_text(presence) + (holding_zero_readable_ ? "" : " with an exception") +
                   "; not an XEG, WTEC-485 or EXCD203MB" +
                   (definitions_.empty() ? std::string() : ", nor a device definition's identify read"));
}

void ModbusProbe::on_reply(const std::optional<protocol::Response>& reply) {
    const auto values = values_of(reply);
    switch (step_) {
        case Step::presence:
            if (!reply) {
                step_ = Step::finished;  // nobody at this address
                return;
            }
            holding_zero_readable_ = values.has_value() && values->size() == 1;
            step_ = Step::xeg_model;
            return;
        case Step::xeg_model:
            if (values && values->size() == 1) {
                if (const auto model = engine::xeg_model_limits(values->front())) {
                    identified(engine::DeviceType::hiwin_xeg,
                               std::string{model->name} + " (model " + engine::hex_word(model->model) + ")");
                    return;
                }
            }
            step_ = Step::wtec_id;
            return;
        case Step::wtec_id:
            if (values && values->size() == 1 && values->front() == address_) {
                identified(engine::DeviceType::wtec_rtu, "device ID register " + span_text(engine::wtec_rtu_identification()) +
                                                             " reads " + std::to_string(address_));
                return;
            }
            step_ = Step::excd_version;
            return;
        case Step::excd_version:
            if (values && values->size() == 2) {
                const std::uint32_t version = (std::uint32_t{(*values)[0]} << 16) | (*values)[1];
                identified(engine::DeviceType::excd203mb,
                           "ver (" + span_text(engine::excd_identification()) + ") reads " + std::to_string(version));
                return;
            }
            try_definitions(0);
            return;
        case Step::definitions: {
            const DefinitionIdentify& candidate = definitions_[definition_];
            const auto& read = candidate.read;
            if (values && values->size() == read.count && (read.expect.empty() || *values == read.expect)) {
                identified(engine::DeviceType::modbus,
                           "device definition " + candidate.name + ": its identify read (" +
                               std::string(core::to_string(read.table)) + " " +
                               span_text(engine::IdentificationRead{read.address, read.count}) +
                               (read.expect.empty() ? ") is answered" : ") reads the expected values"));
                found_->definition = candidate.name;
                return;
            }
            try_definitions(definition_ + 1);
            return;
        }
        case Step::finished: break;
    }
    throw std::logic_error("ModbusProbe::on_reply after the probe of address " + std::to_string(address_) +
                           " finished; call next() first");
}

std::vector<std::uint8_t> parse_stations(protocol::ByteView rx) {
    namespace wtec = protocol::wtec;
    std::vector<std::uint8_t> stations;
    while (!rx.empty()) {
        const auto frame = wtec::scan_frame(rx);
        if (frame.need_more() || frame.consumed == 0) {
            break;  // an unfinished frame at the end: the window closed on it
        }
        if (frame.complete()) {
            const auto reply = wtec::decode_reply(wtec::broadcast_address, wtec::ReadStations{}, frame.value);
            if (reply.complete()) {
                if (const auto* station = std::get_if<wtec::Station>(&reply.value)) {
                    stations.push_back(station->address);
                }
            }
        }
        rx = rx.subspan(std::min(frame.consumed, rx.size()));
    }
    std::sort(stations.begin(), stations.end());
    stations.erase(std::unique(stations.begin(), stations.end()), stations.end());
    return stations;
}

}  // namespace fieldbridge::scan
