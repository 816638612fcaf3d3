"""Runs the real fieldbridge binary for the daemon integration tests.

NotifySocket plays systemd's side of sd_notify(3): a UNIX datagram socket whose
path goes into NOTIFY_SOCKET. Gateway starts the binary with its stderr on a pipe
read by a thread, so that tests wait for log lines with a bound instead of
sleeping. Every wait has a timeout; teardown kills by PID.
"""

import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

from emulation import target_command

# Generous bounds for a loaded 2-core machine and sanitizer builds; a healthy run
# answers in milliseconds.
TIMEOUT = 15.0

# Variables from the environment of the test runner that would change what the
# binary does (it may itself run under systemd).
_SERVICE_VARIABLES = ("NOTIFY_SOCKET", "WATCHDOG_USEC", "WATCHDOG_PID", "JOURNAL_STREAM", "LISTEN_FDS",
                      "LISTEN_PID", "LISTEN_FDNAMES", "INVOCATION_ID")

def _free_port():
    """A loopback port nobody listens on now: daemon tests run in parallel."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


_PORT = {"port": _free_port()}

CONFIG_ONE_LINE = """\
gateway:
  id: itest
  log_level: info
modbus_tcp:
  listen: ["127.0.0.1:%(port)d"]
lines:
  - name: line-a
    port: /dev/fieldbridge-itest-absent-a
    devices:
      - {name: gripper-1, type: hiwin-xeg, address: 1, unit_id: 1}
      - {name: stepper-1, type: excd203mb, address: 2, unit_id: 2}
"""

CONFIG_TWO_LINES = CONFIG_ONE_LINE + """\
  - name: line-b
    port: /dev/fieldbridge-itest-absent-b
    devices:
      - {name: gripper-2, type: wtec-rtu, address: 1, unit_id: 3}
"""

# Line 3, column 3: an unknown key; line 9, column 11: not a standard baud rate.
CONFIG_BROKEN = """\
gateway:
  id: itest
  colour: blue
modbus_tcp:
  listen: ["127.0.0.1:%(port)d"]
lines:
  - name: line-a
    port: /dev/fieldbridge-itest-absent-a
    baud: 12345
    devices:
      - {name: gripper-1, type: hiwin-xeg, address: 1, unit_id: 1}
"""
CONFIG_ONE_LINE, CONFIG_TWO_LINES, CONFIG_BROKEN = (c % _PORT for c in (CONFIG_ONE_LINE, CONFIG_TWO_LINES, CONFIG_BROKEN))


def parse_arguments():
    """argv: <test script> <fieldbridge binary> <project config dir> [unittest args]."""
    if len(sys.argv) < 3:
        sys.exit("usage: %s FIELDBRIDGE_BINARY CONFIG_DIR [unittest options]" % sys.argv[0])
    binary, config_dir = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    return os.path.abspath(binary), os.path.abspath(config_dir)


def clean_environment(extra=None):
    env = {k: v for k, v in os.environ.items() if k not in _SERVICE_VARIABLES}
    # A sanitizer report must fail the test, not scroll by.
    env.setdefault("ASAN_OPTIONS", "abort_on_error=1:detect_leaks=1")
    env.setdefault("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1")
    env.update(extra or {})
    return env


def write_file(directory, name, text):
    path = os.path.join(directory, name)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return path


class NotifySocket:
    """The service manager's end of NOTIFY_SOCKET."""

    def __init__(self, directory):
        self.path = os.path.join(directory, "notify.sock")
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(self.path)
        self.messages = []  # every datagram received, in order
        self._seen = 0

    def close(self):
        self.sock.close()

    def wait_for(self, predicate, what, timeout=TIMEOUT):
        """Returns the first not yet consumed message matching predicate; raises
        AssertionError naming what was awaited when the deadline passes."""
        deadline = time.monotonic() + timeout
        while True:
            while self._seen < len(self.messages):
                message = self.messages[self._seen]
                self._seen += 1
                if predicate(message):
                    return message
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise AssertionError("no %s within %.0f s; received: %r" % (what, timeout, self.messages))
            self.sock.settimeout(remaining)
            try:
                data = self.sock.recv(65536)
            except socket.timeout:
                continue
            self.messages.append(data.decode("utf-8"))

    def wait_for_prefix(self, prefix, timeout=TIMEOUT):
        return self.wait_for(lambda m: m.startswith(prefix), repr(prefix), timeout)

    def drain(self):
        """Reads what is already queued, without waiting."""
        self.sock.setblocking(False)
        try:
            while True:
                self.messages.append(self.sock.recv(65536).decode("utf-8"))
        except BlockingIOError:
            pass
        finally:
            self.sock.setblocking(True)


class Gateway:
    """One fieldbridge process with its stderr collected line by line."""

    def __init__(self, binary, args, env=None, watchdog_pid_is_self=False):
        read_end, write_end = os.pipe()
        info = os.fstat(write_end)
        # systemd.exec(5): JOURNAL_STREAM is "<st_dev>:<st_ino>" of the stderr stream.
        self.pipe_identity = "%d:%d" % (info.st_dev, info.st_ino)
        command = target_command(binary, *args)
        if watchdog_pid_is_self:
            # WATCHDOG_PID must be the PID of the process itself, which is only
            # known after fork: exec from a shell whose PID the binary inherits.
            command = ["/bin/sh", "-c", 'WATCHDOG_PID=$$ exec "$0" "$@"'] + command
        if callable(env):
            env = env(self.pipe_identity)
        self.process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=write_end,
                                        env=env)
        os.close(write_end)
        self.lines = []
        self._condition = threading.Condition()
        self._reader = threading.Thread(target=self._read, args=(read_end,), daemon=True)
        self._reader.start()

    def _read(self, fd):
        with os.fdopen(fd, "r", encoding="utf-8", errors="replace") as stream:
            for line in stream:
                with self._condition:
                    self.lines.append(line.rstrip("\n"))
                    self._condition.notify_all()
        with self._condition:
            self.lines.append(None)  # end of stream
            self._condition.notify_all()

    @property
    def pid(self):
        return self.process.pid

    def stderr_text(self):
        with self._condition:
            return "\n".join(line for line in self.lines if line is not None)

    def wait_for_log(self, text, timeout=TIMEOUT):
        """Returns the first stderr line containing text."""
        def find():
            for line in self.lines:
                if line is None:
                    return "EOF"
                if text in line:
                    return line
            return None

        with self._condition:
            found = self._condition.wait_for(find, timeout)
        if found is None or found == "EOF":
            raise AssertionError("no log line containing %r within %.0f s; stderr so far:\n%s"
                                 % (text, timeout, self.stderr_text()))
        return found

    def send(self, sig):
        self.process.send_signal(sig)

    def running(self):
        return self.process.poll() is None

    def wait_exit(self, timeout=TIMEOUT):
        code = self.process.wait(timeout)
        self._reader.join(timeout)
        return code

    def kill(self):
        """Teardown: kills this process (by its PID) if it still runs."""
        if self.process.poll() is None:
            os.kill(self.process.pid, signal.SIGKILL)
            self.process.wait(TIMEOUT)
        if self.process.stdout:
            self.process.stdout.close()
        self._reader.join(TIMEOUT)


class DaemonTestCase:
    """Mixin for unittest.TestCase: a temporary directory and a process list that
    is cleaned up whatever happens."""

    binary = None
    config_dir = None

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="fb-daemon-")
        self.tmp = self._tmp.name
        self.gateways = []
        self.sockets = []

    def tearDown(self):
        for gateway in self.gateways:
            gateway.kill()
        for sock in self.sockets:
            sock.close()
        self._tmp.cleanup()

    def notify_socket(self):
        sock = NotifySocket(self.tmp)
        self.sockets.append(sock)
        return sock

    def start(self, args, env=None, watchdog_pid_is_self=False):
        gateway = Gateway(self.binary, args, env if env is not None else clean_environment(), watchdog_pid_is_self)
        self.gateways.append(gateway)
        return gateway

    def config(self, text, name="gateway.yaml"):
        return write_file(self.tmp, name, text)

    def run_binary(self, args):
        return subprocess.run(target_command(self.binary, *args), stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              env=clean_environment(), timeout=TIMEOUT)
