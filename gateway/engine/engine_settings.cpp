#include "engine/engine_settings.hpp"

namespace fieldbridge::engine {

DeviceType to_engine(config::DeviceType type) noexcept {
    switch (type) {
        case config::DeviceType::hiwin_xeg: return DeviceType::hiwin_xeg;
        case config::DeviceType::excd203mb: return DeviceType::excd203mb;
        case config::DeviceType::wtec_rtu: return DeviceType::wtec_rtu;
        case config::DeviceType::wtec_ascii: return DeviceType::wtec_ascii;
        case config::DeviceType::modbus: return DeviceType::modbus;
    }
    return DeviceType::modbus;
}

WordOrder to_engine(config::WordOrder order) noexcept {
    return order == config::WordOrder::low_first ? WordOrder::low_first : WordOrder::high_first;
}

Table to_engine(config::RegisterTable table) noexcept {
    switch (table) {
        case config::RegisterTable::coils: return Table::coils;
        case config::RegisterTable::discrete_inputs: return Table::discrete_inputs;
        case config::RegisterTable::holding: return Table::holding;
        case config::RegisterTable::input: return Table::input;
    }
    return Table::holding;
}

SerialSettings serial_settings(const config::LineConfig& line) {
    SerialSettings settings;
    settings.path = line.port;
    settings.baud = line.baud;
    switch (line.parity) {
        case config::Parity::none: settings.parity = 'N'; break;
        case config::Parity::even: settings.parity = 'E'; break;
        case config::Parity::odd: settings.parity = 'O'; break;
    }
    settings.data_bits = line.data_bits;
    settings.stop_bits = line.stop_bits;
    settings.rs485 = line.rs485.enabled;
    settings.rts_on_send = line.rs485.rts_on_send;
    settings.rts_after_send = line.rs485.rts_after_send;
    settings.delay_rts_before_send_ms = static_cast<unsigned>(line.rs485.delay_before_send.count());
    settings.delay_rts_after_send_ms = static_cast<unsigned>(line.rs485.delay_after_send.count());
    return settings;
}

LineTimingConfig line_timing(const config::LineConfig& line) {
    LineTimingConfig timing;
    timing.baud = line.baud;
    timing.data_bits = line.data_bits;
    timing.parity = line.parity != config::Parity::none;
    timing.stop_bits = line.stop_bits;
    timing.response_timeout = line.response_timeout;
    timing.byte_timeout = line.byte_timeout;
    timing.turnaround = line.turnaround;
    timing.broadcast_delay = line.broadcast_delay;
    timing.local_echo = line.local_echo;
    // WTEC-485 ASCII timeouts are the manual's (seed 003, 1.1), not configurable; the
    // frame timeout is never shorter than the line's response timeout, so a slow
    // line configured for its Modbus devices does not cut ASCII replies short.
    timing.ascii_frame_timeout = std::max<Duration>(timing.ascii_frame_timeout, line.response_timeout);
    return timing;
}

LineWorkerConfig line_worker_config(const config::LineConfig& line) {
    LineWorkerConfig worker;
    worker.name = line.name;
    worker.timing = line_timing(line);
    worker.scheduler.line_name = line.name;
    // The port's reopen back-off is the device back-off: both answer "how often may
    // we knock on something that is not there".
    worker.reopen_initial = line.offline_backoff.initial;
    worker.reopen_max = line.offline_backoff.max;
    return worker;
}

DeviceLimits device_limits(const config::LineConfig& line, const config::DeviceConfig& device) {
    DeviceLimits limits;
    limits.queue_limit = device.queue_limit;
    limits.read_retries = line.read_retries;
    limits.offline_after = line.offline_after;
    limits.backoff_initial = line.offline_backoff.initial;
    limits.backoff_max = line.offline_backoff.max;
    return limits;
}

ProfileOptions profile_options(const config::DeviceConfig& device) {
    ProfileOptions options;
    options.address = device.address;
    options.poll.fast = device.poll.fast;
    options.poll.slow = device.poll.slow;
    options.poll.motion = device.poll.motion;
    options.allow_protected = device.allow_protected;
    options.word_order = to_engine(device.word_order);
    options.wtec_stroke = device.stroke;
    for (const auto& block : device.blocks) {
        options.blocks.push_back(GenericBlock{to_engine(block.table), block.address, block.count, block.period,
                                              block.writable});
    }
    return options;
}

DeviceAgentConfig device_agent_config(const config::LineConfig& line, const config::DeviceConfig& device,
                                      DeviceIndex index) {
    DeviceAgentConfig agent;
    agent.name = device.name;
    agent.line_name = line.name;
    agent.index = index;
    agent.address = device.address;
    agent.max_age = device.max_age;
    agent.command_ttl = device.command_ttl;
    agent.delay_before_command = device.delay_before_command;
    agent.motion_period = device.poll.motion;
    return agent;
}

}  // namespace fieldbridge::engine
