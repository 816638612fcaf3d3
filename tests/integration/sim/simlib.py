"""Helpers for the fieldbridge-sim system tests: start the real simulator in a
temporary directory, wait for READY (bounded), talk to its pseudo-terminals in raw
mode and to its control socket. Every wait is bounded; processes are killed by PID.

Python 3 standard library only."""

import json
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import termios
import time
import tty
import unittest

SIM = None  # path of the fieldbridge-sim binary, from --sim or FIELDBRIDGE_SIM

READY_TIMEOUT = 20.0  # sanitizer builds start slowly on a busy 2-core machine
STOP_TIMEOUT = 10.0


def main():
    """unittest.main() after taking --sim PATH off the command line."""
    global SIM
    argv = list(sys.argv)
    if "--sim" in argv:
        i = argv.index("--sim")
        SIM = argv[i + 1]
        del argv[i:i + 2]
    SIM = SIM or os.environ.get("FIELDBRIDGE_SIM")
    if not SIM or not os.access(SIM, os.X_OK):
        sys.exit("give the simulator binary with --sim PATH (or FIELDBRIDGE_SIM)")
    unittest.main(argv=argv, verbosity=2)


# ---- frames ---------------------------------------------------------------------

def crc16(data: bytes) -> int:
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


def rtu(hex_without_crc: str) -> bytes:
    """RTU ADU from hex digits (address + PDU); CRC appended low byte first."""
    body = bytes.fromhex(hex_without_crc)
    crc = crc16(body)
    return body + bytes([crc & 0xFF, crc >> 8])


def crc_ok(adu: bytes) -> bool:
    return len(adu) >= 4 and crc16(adu[:-2]) == (adu[-2] | adu[-1] << 8)


def ascii_frame(body: str) -> bytes:
    """WTEC ASCII frame: '>' + address + command + data, CRC as 4 hex digits, CR LF."""
    assert body.startswith(">")
    return (body + "%04X" % crc16(body.encode())).encode() + b"\r\n"


def h(text: str) -> bytes:
    return bytes.fromhex(text)


def readdress_rtu(adu: bytes, address: int) -> bytes:
    """The same RTU request or reply from another slave address (CRC recomputed): the
    manuals print their examples for ID 1, a shared bus needs other IDs."""
    assert crc_ok(adu), adu.hex(" ")
    return rtu(("%02X" % address) + adu[1:-2].hex())


def readdress_ascii(body: str, address: int) -> bytes:
    """A WTEC ASCII frame body as printed ('>01A63D8', CRC included) for another
    address: '>' + address + command and data, new CRC, CR LF."""
    assert body.startswith(">") and len(body) >= 7, body
    return ascii_frame(">%02X" % address + body[3:-4])


# ---- the manuals' example frames (tests/vectors/vectors.yaml) ---------------------

VECTORS_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir,
                            "vectors", "vectors.yaml")


def _scalar(text):
    text = text.strip()
    if text == "null":
        return None
    if text in ("true", "false"):
        return text == "true"
    if len(text) >= 2 and text[0] == text[-1] == "'":
        return text[1:-1].replace("''", "'")
    return text


def load_vectors(path=VECTORS_PATH):
    """The example frames of the manuals: a list of dicts (protocol, device, what,
    request, response, ...). vectors.yaml is a flat list of one-line scalars, so a
    few lines of parsing replace a YAML library the standard library lacks."""
    items = []
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.rstrip("\n")
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            if line.startswith("- "):
                items.append({})
                line = line[2:]
            elif not line.startswith("  "):
                raise ValueError("%s: unexpected line %r" % (path, line))
            key, sep, value = line.strip().partition(": ")
            if not sep:
                raise ValueError("%s: line %r is not 'key: value'" % (path, line))
            items[-1][key] = _scalar(value)
    return items


def vector(what, vectors=None):
    """The example whose 'what' is @p what: exactly one must match."""
    found = [v for v in (vectors or load_vectors()) if v["what"] == what]
    if len(found) != 1:
        raise KeyError("vectors.yaml has %d examples named %r" % (len(found), what))
    return found[0]


# ---- the simulator process -------------------------------------------------------

class Sim:
    """One fieldbridge-sim process in its own temporary directory."""

    def __init__(self, args, tmp):
        self.tmp = tmp
        self.log_path = os.path.join(tmp, "sim.log")
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen([SIM] + list(args), stdout=subprocess.PIPE,
                                     stderr=self.log, stdin=subprocess.DEVNULL)
        self._wait_ready()

    def _wait_ready(self):
        deadline = time.monotonic() + READY_TIMEOUT
        line = b""
        while time.monotonic() < deadline:
            r, _, _ = select.select([self.proc.stdout], [], [], 0.1)
            if r:
                chunk = os.read(self.proc.stdout.fileno(), 256)
                if not chunk:
                    break
                line += chunk
                if b"READY\n" in line:
                    return
            if self.proc.poll() is not None:
                break
        self.kill()
        raise AssertionError("fieldbridge-sim did not print READY within %.0f s; log:\n%s"
                             % (READY_TIMEOUT, self.log_text()))

    def log_text(self):
        self.log.flush()
        with open(self.log_path, "rb") as f:
            return f.read().decode(errors="replace")

    def terminate(self, timeout=STOP_TIMEOUT):
        """SIGTERM, bounded wait; returns the exit code."""
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGTERM)
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise AssertionError("fieldbridge-sim ignored SIGTERM for %.0f s" % timeout)

    def kill(self):
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGKILL)
            self.proc.wait(timeout=STOP_TIMEOUT)

    def close(self):
        self.kill()
        self.proc.stdout.close()
        self.log.close()


class SimTestCase(unittest.TestCase):
    """Starts simulators with start(). tearDown stops each one still running with
    SIGTERM and requires exit code 0 (so a sanitizer build's leak and shutdown checks
    count), killing it by PID if it does not stop."""

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="fbsim-")
        self.tmp = self._tmp.name
        self.sims = []
        self.fds = []

    def tearDown(self):
        for fd in self.fds:
            try:
                os.close(fd)
            except OSError:
                pass
        result = getattr(getattr(self, "_outcome", None), "result", None)
        failed = result is not None and any(
            test is self for test, _ in list(result.failures) + list(result.errors))
        unclean = []
        for sim in self.sims:
            if sim.proc.poll() is None:  # a sim the test ended itself is its business
                try:
                    code = sim.terminate()
                    if code != 0:
                        unclean.append("exit code %d after SIGTERM" % code)
                except AssertionError as e:
                    unclean.append(str(e))
            if failed or unclean:
                sys.stderr.write("---- simulator log ----\n" + sim.log_text())
            sim.close()
        self._tmp.cleanup()
        if unclean:
            raise AssertionError("fieldbridge-sim did not stop cleanly: " + "; ".join(unclean))

    def path(self, name):
        return os.path.join(self.tmp, name)

    def start(self, *args):
        sim = Sim([str(a) for a in args], self.tmp)
        self.sims.append(sim)
        return sim

    def open_port(self, name):
        fd = open_raw(self.path(name))
        self.fds.append(fd)
        return fd

    def control(self, line):
        return control(self.path("sim.sock"), line)

    def stats(self):
        reply = self.control("stats")
        self.assertTrue(reply.startswith("ok "), reply)
        return json.loads(reply[3:])


def open_raw(path):
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[2] |= termios.CLOCAL | termios.CREAD
    termios.tcsetattr(fd, termios.TCSANOW, attrs)
    termios.tcflush(fd, termios.TCIOFLUSH)
    return fd


def read_for(fd, seconds):
    """Everything that arrives within `seconds`."""
    data = b""
    deadline = time.monotonic() + seconds
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return data
        r, _, _ = select.select([fd], [], [], left)
        if r:
            try:
                data += os.read(fd, 4096)
            except BlockingIOError:
                pass


def read_exactly(fd, count, timeout=2.0):
    """Reads `count` bytes or whatever arrived by the timeout."""
    data = b""
    deadline = time.monotonic() + timeout
    while len(data) < count:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        r, _, _ = select.select([fd], [], [], left)
        if r:
            try:
                data += os.read(fd, count - len(data))
            except BlockingIOError:
                pass
    return data


def read_line(fd, timeout=2.0):
    """Reads up to and including CR LF (WTEC ASCII replies)."""
    data = b""
    deadline = time.monotonic() + timeout
    while not data.endswith(b"\r\n"):
        left = deadline - time.monotonic()
        if left <= 0:
            break
        r, _, _ = select.select([fd], [], [], left)
        if r:
            try:
                data += os.read(fd, 1)
            except BlockingIOError:
                pass
    return data


def transact(fd, request, reply_len, timeout=2.0):
    os.write(fd, request)
    return read_exactly(fd, reply_len, timeout)


def control(sock_path, line, timeout=5.0):
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.settimeout(timeout)
        s.connect(sock_path)
        s.sendall(line.encode() + b"\n")
        data = b""
        while not data.endswith(b"\n"):
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
        return data.decode().rstrip("\n")


def wait_until(predicate, timeout, interval=0.02):
    """Polls `predicate` until it returns a truthy value or `timeout` passes."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            return value
        time.sleep(interval)
