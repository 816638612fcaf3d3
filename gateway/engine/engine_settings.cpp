#include "engine/engine_settings.hpp"

namespace fieldbridge::engine {

SerialSettings serial_settings(const config::LineConfig& line) {
    SerialSettings settings;
    settings.path = line.port;
    if (line.tcp) {
        settings.tcp = StreamEndpoint{line.tcp->host, line.tcp->port, line.connect_timeout};
        return settings;  // the baud and format set the wire-time model only (line_timing)
    }
    settings.baud = line.baud;
    settings.parity = line.parity;
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
    timing.parity = line.parity != core::Parity::none;
    timing.stop_bits = line.stop_bits;
    timing.response_timeout = line.response_timeout;
    timing.byte_timeout = line.byte_timeout;
    timing.turnaround = line.turnaround;
    timing.broadcast_delay = line.broadcast_delay;
    timing.local_echo = line.local_echo;
    timing.request_gap = line.request_gap;
    timing.stream = line.tcp.has_value();
    timing.frame_gap = line.tcp_frame_gap;
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
    if (line.tcp) {
        // A device server: its own key, as the upstreams' (docs/configuration.md).
        worker.reopen_initial = line.reconnect_backoff.initial;
        worker.reopen_max = line.reconnect_backoff.max;
    }
    worker.spin_lead = line.precise_timing ? Duration{config::LineConfig::precise_timing_lead} : Duration::zero();
    return worker;
}

DeviceLimits device_limits(const config::LineConfig& line, const config::DeviceConfig& device) {
    DeviceLimits limits;
    limits.queue_limit = device.queue_limit;
    limits.read_retries = line.read_retries;
    limits.offline_after = line.offline_after;
    limits.backoff_initial = line.offline_backoff.initial;
    limits.backoff_max = line.offline_backoff.max;
    limits.request_gap = device.request_gap;
    limits.first_request_delay = device.first_request_delay;
    return limits;
}

ProfileOptions profile_options(const config::DeviceConfig& device) {
    ProfileOptions options;
    options.address = device.address;
    options.poll.fast = device.poll.fast;
    options.poll.slow = device.poll.slow;
    options.poll.motion = device.poll.motion;
    options.allow_protected = device.allow_protected;
    options.word_order = device.word_order;
    options.wtec_stroke = device.stroke;
    for (const auto& block : device.blocks) {
        options.blocks.push_back(GenericBlock{block.table, block.address, block.count, block.period,
                                              block.writable});
    }
    options.points = device.points;
    options.registers = device.registers;
    options.builtin_state = device.builtin_state;
    return options;
}

DeviceAgentConfig device_agent_config(const config::LineConfig& line, const config::DeviceConfig& device,
                                      DeviceIndex index) {
    DeviceAgentConfig agent;
    agent.name = device.name;
    agent.type_name = device.type_name;
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
