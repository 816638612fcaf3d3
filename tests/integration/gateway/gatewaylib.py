"""End-to-end harness: the real fieldbridge daemon in front of fieldbridge-sim (devices
on pseudo-terminals with wire-time emulation, the R6 on loopback) and, when a test
needs it, a private mosquitto broker. Clients are third-party: pymodbus (Debian's
python3-pymodbus), mbpoll, mosquitto_sub / mosquitto_pub, raw sockets.

Every process is started here and killed by its PID in tearDown; every wait is
bounded; everything listens on 127.0.0.1 on ports the kernel picked free.

argv: <test script> --gateway FIELDBRIDGE --sim FIELDBRIDGE_SIM [unittest options]."""

import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import simlib
from emulation import target_command, target_file

try:
    from pymodbus.client import ModbusTcpClient
    PYMODBUS_ERROR = None
except ImportError as e:  # reported by the tests that need it, as a failure
    ModbusTcpClient = None
    PYMODBUS_ERROR = e

GATEWAY = None  # path of the fieldbridge binary, from --gateway

# Generous bounds for a loaded 2-core machine and sanitizer builds.
START_TIMEOUT = 30.0
STOP_TIMEOUT = 10.0
# How long a sanitizer report may take to be written out before the process is killed.
SANITIZER_REPORT_TIMEOUT = 60.0
IO_TIMEOUT = 5.0
# mosquitto's default log types, plus each subscription (subscribe() waits for it).
BROKER_LOG_TYPES = ("log_type error\nlog_type warning\nlog_type notice\nlog_type information\n"
                    "log_type subscribe\n")


def main():
    """unittest.main() after taking --gateway and --sim off the command line."""
    global GATEWAY
    argv = list(sys.argv)
    for option in ("--gateway", "--sim"):
        if option in argv:
            i = argv.index(option)
            value = argv[i + 1]
            del argv[i:i + 2]
            if option == "--gateway":
                GATEWAY = value
            else:
                simlib.SIM = value
    if not GATEWAY or not os.access(GATEWAY, os.X_OK):
        sys.exit("give the gateway binary with --gateway PATH")
    if not simlib.SIM or not os.access(simlib.SIM, os.X_OK):
        sys.exit("give the simulator binary with --sim PATH")
    unittest.main(argv=argv, verbosity=2)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_port(port, timeout, alive=lambda: True):
    """True once something accepts connections on 127.0.0.1:port."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and alive():
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return True
        except OSError:
            time.sleep(0.05)
    return False


def environment():
    env = dict(os.environ)
    for name in ("NOTIFY_SOCKET", "WATCHDOG_USEC", "WATCHDOG_PID", "LISTEN_FDS", "LISTEN_PID"):
        env.pop(name, None)
    env.setdefault("ASAN_OPTIONS", "abort_on_error=1:detect_leaks=1")
    env.setdefault("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1")
    return env


# ---- Modbus TCP frames ------------------------------------------------------------

def mbap(transaction, unit, pdu):
    return struct.pack(">HHHB", transaction, 0, len(pdu) + 1, unit) + pdu


def recv_exactly(sock, count):
    data = b""
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def read_frame(sock):
    """(transaction, unit, pdu) of the next MBAP frame, None when the peer closed."""
    header = recv_exactly(sock, 7)
    if header is None:
        return None
    transaction, protocol, length, unit = struct.unpack(">HHHB", header)
    assert protocol == 0, header.hex(" ")
    pdu = recv_exactly(sock, length - 1)
    if pdu is None:
        return None
    return transaction, unit, pdu


def closed_by_server(sock, timeout=IO_TIMEOUT):
    sock.settimeout(timeout)
    try:
        return sock.recv(1) == b""
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False


# ---- processes --------------------------------------------------------------------

class Process:
    """A child process whose stderr (and optionally stdout) lines are collected by a
    thread, so tests wait for a line with a bound instead of sleeping."""

    def __init__(self, name, command, log_path, stdout_lines=False, env=None):
        self.name = name
        self.log_path = log_path
        self.log = open(log_path, "wb")
        self.lines = []
        self._condition = threading.Condition()
        self.proc = subprocess.Popen(command, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE if stdout_lines else self.log,
                                     stderr=self.log if stdout_lines else subprocess.PIPE,
                                     env=env)
        stream = self.proc.stdout if stdout_lines else self.proc.stderr
        self._reader = threading.Thread(target=self._read, args=(stream,), daemon=True)
        self._reader.start()

    def _read(self, stream):
        for raw in iter(stream.readline, b""):
            line = raw.decode("utf-8", errors="replace").rstrip("\n")
            with self._condition:
                self.lines.append(line)
                self._condition.notify_all()
            if not isinstance(self, Subscriber):
                self.log.write(raw)
                self.log.flush()
        with self._condition:
            self.lines.append(None)
            self._condition.notify_all()

    @property
    def pid(self):
        return self.proc.pid

    def running(self):
        return self.proc.poll() is None

    def text(self):
        with self._condition:
            return "\n".join(line for line in self.lines if line is not None)

    def report(self):
        """What a failed test prints of this process: its log."""
        return _read(self.log_path)

    def wait_line(self, predicate, timeout, start=0):
        """Index and text of the first line from `start` on that satisfies predicate,
        or None at the deadline or end of stream."""
        def find():
            for i in range(start, len(self.lines)):
                line = self.lines[i]
                if line is None:
                    return (-1, None)
                if predicate(line):
                    return (i, line)
            return None

        with self._condition:
            found = self._condition.wait_for(find, timeout)
        if not found or found[1] is None:
            return None
        return found

    def mark(self):
        """The index the next line will have (a start for wait_line)."""
        with self._condition:
            return len(self.lines)

    def signal(self, sig):
        if self.running():
            os.kill(self.proc.pid, sig)

    def wait_exit(self, timeout=STOP_TIMEOUT):
        return self.proc.wait(timeout)

    def kill(self):
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGKILL)
            self.proc.wait(STOP_TIMEOUT)
        self._reader.join(STOP_TIMEOUT)
        for stream in (self.proc.stdout, self.proc.stderr):
            if stream:
                stream.close()
        self.log.close()


class Subscriber(Process):
    """mosquitto_sub printing 'retained-flag topic payload' per message."""

    def messages(self, topic, start=0):
        with self._condition:
            found = []
            for line in self.lines[start:]:
                if line is None:
                    break
                retained, got_topic, payload = line.split(" ", 2)
                if got_topic == topic:
                    found.append((retained == "1", payload))
            return found

    def wait_message(self, topic, predicate=lambda payload: True, timeout=IO_TIMEOUT, start=0):
        """(retained, payload) of the first message on topic satisfying predicate."""
        def match(line):
            retained, got_topic, payload = line.split(" ", 2)
            return got_topic == topic and predicate(payload)

        found = self.wait_line(match, timeout, start)
        if found is None:
            return None
        retained, _, payload = found[1].split(" ", 2)
        return retained == "1", payload



def json_predicate(check):
    def predicate(payload):
        try:
            return check(json.loads(payload))
        except (ValueError, KeyError, TypeError):
            return False
    return predicate


# ---- the test case ----------------------------------------------------------------

# Timeouts are generous (300 ms reply, 2 s command deadline): the tests run beside
# sanitizer builds on a loaded 2-core machine, and a write that times out is never
# retried (spec section 3 rule 6).
CELL_CONFIG = """\
gateway:
  id: e2e
  log_level: info
modbus_tcp:
  listen: ["127.0.0.1:{tcp_port}"]
  max_connections: {max_connections}
  idle_timeout: 60s
{rules}lines:
  - name: line-a
    port: {tmp}/line-a
    baud: 115200
    response_timeout: 300ms
    broadcast_unit: 100
    devices:
      - {{name: gripper-1, type: hiwin-xeg, address: 2, unit_id: 1, command_ttl: 2s}}
      - {{name: stepper-1, type: excd203mb, address: 3, unit_id: 2, command_ttl: 2s}}
      - {{name: gripper-2, type: wtec-ascii, address: 5, unit_id: 3, stroke: 20000, command_ttl: 2s}}
{extra_devices_a}  - name: line-b
    port: {tmp}/line-b
    baud: 115200
    response_timeout: 300ms
    devices:
      - {{name: gripper-3, type: wtec-rtu, address: 1, unit_id: 4, command_ttl: 2s}}
{extra_devices_b}{extra_lines}{upstreams}{mqtt}{metrics}"""

UPSTREAM_CONFIG = """\
upstreams:
  - name: r6
    host: 127.0.0.1
    port: {r6_port}
    units:
      - {{unit_id: 50, upstream_unit: 1, name: r6}}
"""

MQTT_CONFIG = """\
mqtt:
  uri: tcp://127.0.0.1:{mqtt_port}
  qos: 1
  keep_alive: 2s
  heartbeat: 30s
  min_interval: 100ms
  diag_period: 60s
  reconnect_backoff: {{initial: 200ms, max: 1s}}
"""


METRICS_CONFIG = """\
metrics_http:
  listen: 127.0.0.1:{metrics_port}
"""


class CellTestCase(unittest.TestCase):
    """A simulated cell: fieldbridge-sim with line-a (XEG @2 unit 1, EXCD203MB @3 unit 2,
    WTEC ASCII @5 unit 3, broadcast unit 100) and line-b (WTEC RTU @1 unit 4), the
    gateway in front of it, optionally the R6 (unit 50) and a broker.

    A test case may set, before start_cell(): mqtt_config (the gateway's `mqtt:`
    section, formatted with mqtt_port), broker_listener (mosquitto's listener lines
    after `listener PORT 127.0.0.1`, e.g. TLS files), broker_persistence (True: the
    broker keeps retained messages and persistent sessions across a stop_broker() /
    start_broker()) and mqtt_client_args (added to every mosquitto_sub /
    mosquitto_pub, e.g. --cafile)."""

    mqtt_config = MQTT_CONFIG
    broker_listener = "allow_anonymous true\n"
    broker_persistence = False
    mqtt_client_args = ()

    def setUp(self):
        if PYMODBUS_ERROR is not None:
            self.fail("python3-pymodbus is needed: %s" % PYMODBUS_ERROR)
        self._tmp = tempfile.TemporaryDirectory(prefix="fb-e2e-")
        self.tmp = self._tmp.name
        self.processes = []
        self.sim = None
        self.gateway = None
        self.broker = None
        self._subscribers = 0
        self.clients = []

    def tearDown(self):
        for client in self.clients:
            client.close()
        result = getattr(getattr(self, "_outcome", None), "result", None)
        failures = [] if result is None else [
            text for test, text in list(result.failures) + list(result.errors) if test is self]
        failed = bool(failures)
        if failed:
            # The failure first: CI keeps the head and the tail of a long output.
            sys.stderr.write("---- %s failed ----\n%s\n" % (self.id(), failures[-1]))
        # The gateway and the simulator still running are stopped with SIGTERM and must
        # exit 0, so that a sanitizer build's leak and shutdown checks count.
        unclean = []
        for process in reversed(self.processes):
            if process is self.gateway and process.running():
                process.signal(signal.SIGTERM)
                try:
                    code = process.wait_exit()
                    if code != 0:
                        unclean.append("fieldbridge exited with %d after SIGTERM" % code)
                except subprocess.TimeoutExpired:
                    if "Sanitizer" in _read(process.log_path):
                        # A sanitizer report is being written (symbolising takes long on a
                        # loaded machine): let it finish, so that the log shows the stack.
                        try:
                            process.wait_exit(SANITIZER_REPORT_TIMEOUT)
                        except subprocess.TimeoutExpired:
                            pass
                        unclean.append("fieldbridge failed a sanitizer check while stopping (its log below)")
                    else:
                        unclean.append("fieldbridge ignored SIGTERM for %.0f s" % STOP_TIMEOUT)
            process.kill()
            if failed or unclean:
                sys.stderr.write("---- %s log ----\n%s\n" % (process.name, process.report()))
        if self.sim is not None:
            if self.sim.proc.poll() is None:
                try:
                    code = self.sim.terminate()
                    if code != 0:
                        unclean.append("fieldbridge-sim exited with %d after SIGTERM" % code)
                except AssertionError as e:
                    unclean.append(str(e))
            if failed or unclean:
                sys.stderr.write("---- simulator log ----\n" + self.sim.log_text())
            self.sim.close()
        self._tmp.cleanup()
        if unclean:
            raise AssertionError("; ".join(unclean))

    def path(self, name):
        return os.path.join(self.tmp, name)

    # -- starting --------------------------------------------------------------------

    def start_cell(self, r6=False, mqtt=False, extra_devices_a="", extra_devices_b="", extra_lines="",
                   rules="", max_connections=64, sim_line_b="wtec-rtu@1", sim_extra=(), before_gateway=None,
                   launcher=None, wait_ready=True, metrics=False):
        """Simulator, broker (mqtt=True), before_gateway() if given, gateway; returns
        when the gateway is ready (wait_ready=False: as soon as it was started).
        launcher() returns the command line put before the gateway's own (e.g.
        systemd-socket-activate), called once the ports are chosen. metrics=True: the
        Prometheus endpoint on 127.0.0.1:self.metrics_port."""
        self.tcp_port = free_port()
        self.r6_port = free_port() if r6 else None
        self.metrics_port = free_port() if metrics else None
        args = ["--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                "--bus", self.path("line-b") + ":" + sim_line_b,
                "--control", self.path("sim.sock"), "--wire-time", "--baud", "115200"]
        if r6:
            args += ["--r6", "127.0.0.1:%d" % self.r6_port]
        self.sim = simlib.Sim(args + list(sim_extra), self.tmp)
        if mqtt:
            self.mqtt_port = free_port()
            self.start_broker()
        if before_gateway is not None:
            before_gateway()
        config = CELL_CONFIG.format(
            tcp_port=self.tcp_port, tmp=self.tmp, max_connections=max_connections,
            extra_devices_a=extra_devices_a, extra_devices_b=extra_devices_b, extra_lines=extra_lines,
            rules=rules,
            upstreams=UPSTREAM_CONFIG.format(r6_port=self.r6_port) if r6 else "",
            mqtt=self.mqtt_config.format(mqtt_port=self.mqtt_port) if mqtt else "",
            metrics=METRICS_CONFIG.format(metrics_port=self.metrics_port) if metrics else "")
        self.config_path = self.path("gateway.yaml")
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(config)
        self.start_gateway(launcher() if launcher else (), wait_ready)

    def rewrite_config(self, old, new):
        """Replaces the first `old` of the gateway's configuration file by `new` (for a
        reload); fails when `old` is not there."""
        with open(self.config_path, encoding="utf-8") as f:
            text = f.read()
        self.assertIn(old, text)
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(text.replace(old, new, 1))

    def reload(self, timeout=15.0):
        """SIGHUP to the gateway; returns once it logged that the reload was applied."""
        mark = self.gateway.mark()
        self.gateway.signal(signal.SIGHUP)
        if self.gateway.wait_line(lambda line: "configuration reloaded" in line, timeout, start=mark) is None:
            self.fail("reload not applied:\n%s" % self.gateway.text())

    def start_gateway(self, launcher=(), wait_ready=True):
        self.gateway = Process("fieldbridge", list(launcher) + target_command(GATEWAY, "--config", self.config_path),
                               self.path("gateway.log"), env=environment())
        self.processes.append(self.gateway)
        if wait_ready:
            self.wait_ready()

    def wait_ready(self):
        if self.gateway.wait_line(lambda line: "ready:" in line, START_TIMEOUT) is None:
            self.fail("fieldbridge did not log 'ready:' within %.0f s:\n%s"
                      % (START_TIMEOUT, self.gateway.text()))

    def start_broker(self):
        conf = self.path("mosquitto.conf")
        with open(conf, "w", encoding="utf-8") as f:
            f.write("listener %d 127.0.0.1\n%s%s%s"
                    % (self.mqtt_port, self.broker_listener, self._persistence(), BROKER_LOG_TYPES))
        self.broker = Process("mosquitto", ["mosquitto", "-c", conf], self.path("mosquitto.log"))
        self.processes.append(self.broker)
        if not wait_port(self.mqtt_port, START_TIMEOUT, self.broker.running):
            self.fail("mosquitto did not listen on %d:\n%s" % (self.mqtt_port, _read(self.broker.log_path)))

    def _persistence(self):
        if not self.broker_persistence:
            return "persistence false\n"
        # mosquitto started as root runs as user mosquitto: it must write there.
        directory = self.path("broker-db")
        if not os.path.isdir(directory):
            os.chmod(self.tmp, 0o711)
            os.mkdir(directory)
            os.chmod(directory, 0o777)
        return "persistence true\npersistence_location %s/\n" % directory

    def stop_broker(self):
        self.broker.signal(signal.SIGTERM)
        self.broker.wait_exit()
        self.processes.remove(self.broker)
        self.broker.kill()

    def subscribe(self, *topics, session=None):
        """mosquitto_sub on topics; session: a client id for a persistent session (with
        broker_persistence it gets, once it has reconnected by itself, what was
        published while the broker was restarting)."""
        command = ["mosquitto_sub", "-h", "127.0.0.1", "-p", str(self.mqtt_port), "-q", "1",
                   "-F", "%r %t %p"] + list(self.mqtt_client_args)
        self._subscribers += 1
        client_id = session if session is not None else "fb-sub-%d" % self._subscribers
        command += ["-i", client_id] + (["-c"] if session is not None else [])
        for topic in topics:
            command += ["-t", topic]
        broker_mark = self.broker.mark()
        sub = Subscriber("mosquitto_sub", command, self.path("sub-%d.log" % self._subscribers),
                         stdout_lines=True)
        self.processes.append(sub)
        # mosquitto_sub prints nothing when subscribed; the broker logs each topic of a
        # SUBSCRIBE as it adds it ("<client id> <qos> <topic>", log_type subscribe):
        # the last topic's line means the subscription is in place.
        suffix = " %s 1 %s" % (client_id, topics[-1])
        if self.broker.wait_line(lambda line: line.endswith(suffix), START_TIMEOUT, broker_mark) is None:
            self.fail("mosquitto did not log the subscription of %s to %s:\n%s"
                      % (client_id, topics[-1], self.broker.text()))
        return sub

    def publish(self, topic, payload, retain=False):
        command = ["mosquitto_pub", "-h", "127.0.0.1", "-p", str(self.mqtt_port), "-q", "1",
                   "-t", topic, "-m", payload] + list(self.mqtt_client_args)
        if retain:
            command.append("-r")
        done = subprocess.run(command, capture_output=True, text=True, timeout=IO_TIMEOUT)
        self.assertEqual(done.returncode, 0, done.stderr)

    # -- clients ---------------------------------------------------------------------

    def client(self):
        client = ModbusTcpClient("127.0.0.1", port=self.tcp_port, timeout=IO_TIMEOUT, retries=0)
        self.assertTrue(client.connect(), "pymodbus cannot connect to the gateway")
        self.clients.append(client)
        return client

    def raw(self):
        sock = socket.create_connection(("127.0.0.1", self.tcp_port), timeout=IO_TIMEOUT)
        self.clients.append(sock)
        return sock

    def control(self, line):
        reply = simlib.control(self.path("sim.sock"), line)
        self.assertTrue(reply.startswith("ok"), "%s -> %s" % (line, reply))
        return reply

    def sim_stats(self):
        return json.loads(self.control("stats")[3:])

    def device_frames(self, bus, address):
        return self.sim_stats()["buses"][bus]["devices"][str(address)]["frames"]

    def bus_trace(self, bus):
        """The frames on `bus` in order, as ("request" | "reply", "02 03 ...") pairs, from
        the simulator's trace log (start_cell(sim_extra=("--log-level", "trace")))."""
        trace = []
        for line in self.sim.log_text().splitlines():
            found = _TRACE_LINE.search(line)
            if found and found.group(1) == bus:
                trace.append(("request" if found.group(2) == "request" else "reply", found.group(3)))
        return trace

    def assert_exchange(self, trace, request, reply, start=0):
        """Index after the first `request` at or after `start` in `trace` that is followed
        by `reply` (None: by no reply, as for a broadcast). The frames are spelled as in
        the manuals' tables ("02 10 06 00 ...")."""
        for i in range(start, len(trace)):
            if trace[i] != ("request", request):
                continue
            following = trace[i + 1] if i + 1 < len(trace) else None
            if reply is None and (following is None or following[0] == "request"):
                return i + 1
            if reply is not None and following == ("reply", reply):
                return i + 2
        self.fail("no request %s answered by %s on the line after frame %d; the line carried:\n%s"
                  % (request, reply, start, "\n".join("%s %s" % f for f in trace[start:])))

    # -- assertions ------------------------------------------------------------------

    def assert_ok(self, reply):
        self.assertFalse(reply.isError(), reply)
        return reply

    def assert_exception(self, reply, code):
        self.assertTrue(reply.isError(), "expected exception 0x%02X, got %r" % (code, reply))
        self.assertEqual(getattr(reply, "exception_code", None), code, reply)

    def read_holding(self, client, address, count, unit):
        return self.assert_ok(client.read_holding_registers(address, count=count, slave=unit)).registers

    def read_input(self, client, address, count, unit):
        return self.assert_ok(client.read_input_registers(address, count=count, slave=unit)).registers

    def wait_value(self, read, expected, timeout, what):
        """Polls read() until it returns expected (bounded); returns the last value."""
        last = [None]

        def check():
            last[0] = read()
            return last[0] == expected
        simlib.wait_until(check, timeout, interval=0.05)
        self.assertEqual(last[0], expected, "%s never became %r" % (what, expected))


_TRACE_LINE = re.compile(r"(\S+): (request|reply \S+) ([0-9A-F]{2}(?: [0-9A-F]{2})*)$")


def rss_kib(pid):
    """The resident set of process @p pid in KiB (a bound on what a client may cost)."""
    with open("/proc/%d/status" % pid, encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS for %d" % pid)


def _read(path):
    try:
        with open(path, "rb") as f:
            return f.read().decode(errors="replace")
    except OSError:
        return ""
