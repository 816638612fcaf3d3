"""Lines behind serial device servers (issue 27): the real gateway reaches the
simulator's buses through loopback TCP ports (devserverlib.DeviceServer, a device
server in transparent mode in front of each pseudo-terminal) on `port: tcp://...`.
Reads, writes, broadcast and WTEC ASCII work as on a tty; a write goes before queued
reads; replies split across segments are joined; a late reply and two replies in one
segment are never matched to the next request; a device's request_gap paces it; a
server that closes mid-reply or refuses connections for a while is reconnected
(within a second of its return); a reload never opens a second connection; `scan --port tcp://` scans through it; and
check-config refuses serial-only options and names that do not resolve."""

import signal
import subprocess
import threading
import time

import devserverlib
import emulation
import gatewaylib
import simlib

XEG, EXCD, WTEC_ASCII, METER, BROADCAST = 1, 2, 3, 10, 100
XEG_MODEL, XEG_FIRMWARE = 0x0600, 0x0303
WTEC_POSITION = 512  # the WTEC uniform view (docs/registers.md)
GATEWAY_TIMEOUT = 0x0B
PATH_DOWN = 0x0A

CONFIG = """\
gateway:
  id: ds
  log_level: info
modbus_tcp:
  listen: ["127.0.0.1:{tcp_port}"]
  idle_timeout: 60s
lines:
  - name: line-a
    port: tcp://127.0.0.1:{port_a}
    baud: 115200
    response_timeout: 300ms
    tcp_frame_gap: 50ms
    broadcast_unit: 100
    devices:
      - {{name: gripper-1, type: hiwin-xeg, address: 2, unit_id: 1, command_ttl: 2s}}
      - {{name: stepper-1, type: excd203mb, address: 3, unit_id: 2, command_ttl: 2s}}
      - {{name: gripper-2, type: wtec-ascii, address: 5, unit_id: 3, stroke: 20000, command_ttl: 2s}}
  - name: line-m
    port: tcp://127.0.0.1:{port_m}
    baud: 115200
    response_timeout: {meter_timeout}
    read_retries: 0
    tcp_frame_gap: 50ms
    devices:
      - name: meter
        type: modbus
        address: 1
        unit_id: 10
        max_age: 0ms
        command_ttl: 2s{meter_extra}
        blocks:
          - {{table: holding, address: 0, count: 1, period: 1h, writable: true}}
          - {{table: holding, address: 10, count: 1, period: 1h, writable: true}}
"""


class DeviceServerCell(gatewaylib.CellTestCase):

    def start_servers_and_gateway(self, meter_timeout="200ms", meter_extra=""):
        self.tcp_port = gatewaylib.free_port()
        self.sim = simlib.Sim(["--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                               "--bus", self.path("line-m") + ":modbus@1",
                               "--control", self.path("sim.sock"), "--wire-time", "--baud", "115200"], self.tmp)
        self.server_a = devserverlib.DeviceServer(self.path("line-a"))
        self.server_m = devserverlib.DeviceServer(self.path("line-m"))
        self.addCleanup(self.server_a.close)
        self.addCleanup(self.server_m.close)
        self.config_path = self.path("gateway.yaml")
        self.meter_extra = meter_extra
        self.write_config(meter_timeout)
        self.start_gateway()
        self.client_ = self.client()
        # Both lines connected and answering.
        self.wait_value(lambda: self.read_holding(self.client_, XEG_MODEL, 1, XEG), [0x0A20], 10, "XEG model")
        self.wait_value(lambda: self.meter(0) is not None, True, 10, "the meter")

    def write_config(self, meter_timeout):
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(CONFIG.format(tcp_port=self.tcp_port, port_a=self.server_a.port, port_m=self.server_m.port,
                                  meter_timeout=meter_timeout, meter_extra=self.meter_extra))

    def meter(self, register):
        reply = self.client_.read_holding_registers(register, count=1, slave=METER)
        return None if reply.isError() else reply.registers[0]

    def set_meter(self, register, value):
        self.assert_ok(self.client_.write_register(register, value, slave=METER))

    # -- what works as on a tty ----------------------------------------------------------

    def test_reads_writes_broadcast_and_wtec_ascii(self):
        self.start_servers_and_gateway()
        client = self.client_
        self.assertEqual(self.read_input(client, XEG_FIRMWARE, 4, XEG), [3, 0, 1, 884])
        self.assert_ok(client.write_registers(XEG_MODEL, [0x0A30], slave=XEG))
        self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A30])
        # The WTEC ASCII gripper, through its RTU register view.
        self.assertEqual(len(self.read_holding(client, WTEC_POSITION, 1, WTEC_ASCII)), 1)
        # Broadcast: written once on the far side's line, no reply awaited.
        before = self.sim_stats()["buses"]["line-a"]["broadcasts"]
        self.assert_ok(client.write_registers(XEG_MODEL, [0x0A20], slave=BROADCAST))
        simlib.wait_until(lambda: self.sim_stats()["buses"]["line-a"]["broadcasts"] > before, 5)
        self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A20])
        self.set_meter(10, 4242)
        self.assertEqual(self.meter(10), 4242)
        # One connection per device server, never a second one.
        self.assertEqual((self.server_a.accepted, self.server_a.turned_away), (1, 0))
        self.assertEqual((self.server_m.accepted, self.server_m.turned_away), (1, 0))
        self.assertIn("line line-a: tcp://127.0.0.1:%d open, connected to 127.0.0.1:%d (TCP_NODELAY"
                      % (self.server_a.port, self.server_a.port), self.gateway.text())

    def test_a_write_goes_before_queued_reads(self):
        # What is measured is the order of the queue, not the line's timeout: 1 s, so
        # that a stall of the Python relay on a loaded machine (CI once saw one past
        # 200 ms under qemu-user) does not fail a read.
        self.start_servers_and_gateway(meter_timeout="1s")
        stop = threading.Event()
        reads = []
        failures = []

        def load():
            client = self.client()
            while not stop.is_set():
                started = time.monotonic()
                reply = client.read_holding_registers(0, count=1, slave=METER)
                ok = not reply.isError()
                if not ok:
                    failures.append(repr(reply))
                reads.append((time.monotonic() - started, ok))

        workers = [threading.Thread(target=load) for _ in range(4)]
        for worker in workers:
            worker.start()
        try:
            time.sleep(0.5)
            writes = []
            for value in range(5):
                started = time.monotonic()
                self.set_meter(10, value)
                writes.append(time.monotonic() - started)
                time.sleep(0.05)
        finally:
            stop.set()
            for worker in workers:
                worker.join(10)
        self.assertEqual(failures, [], "reads failed under load")
        self.assertTrue(all(ok for _, ok in reads))
        read_times = sorted(t for t, _ in reads)
        median_read = read_times[len(read_times) // 2]
        print("under load: %d reads, median %.1f ms; writes %s ms"
              % (len(reads), median_read * 1e3, ", ".join("%.1f" % (w * 1e3) for w in writes)))
        # Four clients keep four reads queued: a read waits for the others, a write
        # only for the one in flight.
        self.assertLess(sorted(writes)[len(writes) // 2], median_read)
        self.assertEqual(self.meter(10), 4)

    def test_replies_split_across_segments(self):
        self.start_servers_and_gateway()
        self.set_meter(0, 1234)
        # Below tcp_frame_gap (50 ms here: the relay is a Python thread on a shared
        # machine, its 2 ms sleep may last much longer).
        self.server_m.split_gap = self.server_a.split_gap = 0.002
        self.server_m.set_mode("split")
        self.server_a.set_mode("split")
        for _ in range(10):
            self.assertEqual(self.meter(0), 1234)
            self.assertEqual(self.read_input(self.client_, XEG_FIRMWARE, 4, XEG), [3, 0, 1, 884])

    def test_a_paced_device_waits_its_request_gap(self):
        self.start_servers_and_gateway(meter_extra="\n        request_gap: 150ms")
        xeg_client = self.client()
        self.meter(0)
        started = time.monotonic()
        for _ in range(4):
            self.assertIsNotNone(self.meter(0))
        paced = time.monotonic() - started
        xeg_started = time.monotonic()
        for _ in range(4):
            self.assertEqual(self.read_input(xeg_client, XEG_FIRMWARE, 4, XEG), [3, 0, 1, 884])
        print("4 paced meter reads: %.0f ms; 4 XEG reads on the other line: %.0f ms"
              % (paced * 1e3, (time.monotonic() - xeg_started) * 1e3))
        self.assertGreaterEqual(paced, 4 * 0.150)

    # -- replies that are not the answer -------------------------------------------------

    def check_held_reply_not_matched(self, mode):
        """The meter's reply to a read of register 0 is held by the device server
        (`mode`) past its timeout; the next read (same device, function and length) of
        register 10 gets its own value, never the held one."""
        self.start_servers_and_gateway()
        self.set_meter(0, 111)
        self.set_meter(10, 222)
        self.server_m.set_mode(mode)
        self.assert_exception(self.client_.read_holding_registers(0, count=1, slave=METER), GATEWAY_TIMEOUT)
        self.assertEqual(self.meter(10), 222)
        self.assertEqual(self.meter(0), 111)

    def test_a_late_reply_is_never_matched_to_the_next_request(self):
        # It arrives just after the next request was written. The gateway tells it by
        # time: it came before the request could have left the device server (the
        # request's wire time after the write). Under qemu-user the daemon handles the
        # bytes milliseconds after they came, past that instant, so the rule cannot
        # hold there (docs/configuration.md, "Lines on tcp:// ports": what a loop
        # that reads late lets through); the merged case below needs no clock.
        if emulation.emulated():
            self.skipTest("a timing rule on the loop's clock: qemu-user's loop reads too late to see it")
        self.check_held_reply_not_matched("late")

    def test_two_replies_in_one_segment_the_newest_answers(self):
        # It arrives in one segment with the next request's reply.
        self.check_held_reply_not_matched("merge")

    # -- the connection's life -----------------------------------------------------------

    def test_server_closing_mid_reply(self):
        self.start_servers_and_gateway()
        self.set_meter(0, 77)
        self.server_m.set_mode("cut")
        reply = self.client_.read_holding_registers(0, count=1, slave=METER)
        self.assertTrue(reply.isError(), reply)
        self.assertIn(reply.exception_code, (GATEWAY_TIMEOUT, PATH_DOWN))
        self.wait_value(lambda: self.meter(0), 77, 5, "the meter after the reconnect")
        self.assertEqual(self.server_m.accepted, 2)
        self.assertIn("closed the connection", self.gateway.text())
        # The other line never noticed.
        self.assertEqual(self.server_a.accepted, 1)

    def test_refused_for_a_while_then_back_within_a_second(self):
        self.start_servers_and_gateway()
        self.set_meter(0, 55)
        self.server_m.refuse()
        self.wait_value(lambda: self.client_.read_holding_registers(0, count=1, slave=METER).isError(), True, 5,
                        "an exception while the device server is gone")
        reply = self.client_.read_holding_registers(0, count=1, slave=METER)
        self.assert_exception(reply, PATH_DOWN)
        simlib.wait_until(lambda: "Connection refused" in self.gateway.text(), 5)
        self.assertIn("Connection refused", self.gateway.text())
        # The rest of the gateway keeps running.
        self.assertEqual(self.read_input(self.client_, XEG_FIRMWARE, 4, XEG), [3, 0, 1, 884])
        time.sleep(2.0)
        back = time.monotonic()
        self.server_m.listen()
        self.wait_value(lambda: self.meter(0), 55, 3, "the meter after the device server came back")
        recovered = time.monotonic() - back
        print("line recovered %.0f ms after the device server came back" % (recovered * 1e3))
        self.assertLess(self.server_m.accepted_at[-1] - back, 1.0)
        self.assertLess(recovered, 1.5)
        self.assertEqual(self.server_m.turned_away, 0)

    def test_a_reload_never_opens_a_second_connection(self):
        self.start_servers_and_gateway()
        mark = len(self.gateway.text().splitlines())
        self.write_config("250ms")  # line-m's timing changed: the line restarts
        self.gateway.signal(signal.SIGHUP)
        if self.gateway.wait_line(lambda line: "configuration reloaded" in line, 10, start=mark) is None:
            self.fail("reload not applied:\n%s" % self.gateway.text())
        self.wait_value(lambda: self.meter(0) is not None, True, 5, "the meter after the reload")
        self.assertEqual(self.server_m.accepted, 2)  # closed, then opened again
        self.assertEqual(self.server_m.turned_away, 0)
        self.assertEqual(self.server_a.accepted, 1)  # unchanged line: kept

    def test_scan_through_the_device_server(self):
        self.tcp_port = gatewaylib.free_port()
        self.sim = simlib.Sim(["--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                               "--wire-time", "--baud", "115200"], self.tmp)
        server = devserverlib.DeviceServer(self.path("line-a"))
        self.addCleanup(server.close)
        port = "tcp://127.0.0.1:%d" % server.port
        result = subprocess.run(emulation.target_command(gatewaylib.GATEWAY, "scan", "--port", port, "--from", "1",
                                                         "--to", "6"), capture_output=True, text=True, timeout=60)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("port: " + port, result.stdout)
        for kind in ("hiwin-xeg", "excd203mb", "wtec-ascii"):
            self.assertIn(kind, result.stdout)
        refused = subprocess.run(emulation.target_command(gatewaylib.GATEWAY, "scan", "--port",
                                                          "tcp://127.0.0.1:%d" % gatewaylib.free_port()),
                                 capture_output=True, text=True, timeout=60)
        self.assertNotEqual(refused.returncode, 0)
        self.assertIn("Connection refused", refused.stderr)


class DeviceServerConfig(gatewaylib.CellTestCase):
    """check-config on tcp:// ports (no cell needed)."""

    def check(self, line_keys, port="tcp://127.0.0.1:4001"):
        path = self.path("c.yaml")
        with open(path, "w", encoding="utf-8") as f:
            f.write("gateway: {id: c}\nlines:\n  - name: a\n    port: %s\n%s    devices:\n"
                    "      - {name: d, type: hiwin-xeg, address: 1, unit_id: 1}\n" % (port, line_keys))
        return subprocess.run(emulation.target_command(gatewaylib.GATEWAY, "--check-config", path),
                              capture_output=True, text=True, timeout=30)

    def test_serial_only_options_and_unresolvable_hosts_are_errors(self):
        self.assertEqual(self.check("").returncode, 0)
        result = self.check("    rs485: {enabled: true}\n    local_echo: true\n")
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("lines[0].rs485: rs485 does not apply to a tcp:// port", result.stderr)
        self.assertIn("lines[0].local_echo: local_echo does not apply to a tcp:// port", result.stderr)
        result = self.check("", port="tcp://no-such-device-server.invalid:4001")
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("host 'no-such-device-server.invalid' does not resolve", result.stderr)


if __name__ == "__main__":
    gatewaylib.main()
