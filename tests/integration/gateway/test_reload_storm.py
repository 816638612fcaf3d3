"""A storm of reloads that swap the device being read (issue 24 item 6): 50 reloads in a
row change gripper-4's slow poll period, so each builds a new agent for it on the running
line, while three clients read it without pause (max_age 0: every read goes to the line).
docs/service.md says what the old agent had queued still goes out and is answered, and a
swap costs no request: no read may fail."""

import collections
import signal
import threading
import time

import gatewaylib as gl
import simlib

XEG_POSITION = 0x0300
READ_UNIT = 5
RELOADS = 50
BEFORE = "max_age: 0ms, command_ttl: 2s}"
AFTER = "max_age: 0ms, command_ttl: 2s, poll: {slow: 900ms}}"


class Reader(threading.Thread):
    """Reads unit 5 back to back on its own connection; counts answers by kind."""

    def __init__(self, case):
        super().__init__(daemon=True)
        self.client = case.client()
        self.stop = threading.Event()
        self.outcomes = collections.Counter()

    def run(self):
        deadline = time.monotonic() + 120  # bounded whatever happens
        while not self.stop.is_set() and time.monotonic() < deadline:
            try:
                reply = self.client.read_input_registers(XEG_POSITION, count=2, slave=READ_UNIT)
                if reply.isError():
                    self.outcomes["exception 0x%02X" % getattr(reply, "exception_code", 0)] += 1
                else:
                    self.outcomes["ok"] += 1
            except Exception as error:  # pylint: disable=broad-except
                self.outcomes[type(error).__name__] += 1


class ReloadStorm(gl.CellTestCase):

    def test_swapping_the_read_device_fails_no_request(self):
        self.start_cell(sim_line_b="wtec-rtu@1,hiwin-xeg@2",
                        extra_devices_b="      - {name: gripper-4, type: hiwin-xeg, address: 2, unit_id: 5, "
                                        + BEFORE + "\n")
        readers = [Reader(self) for _ in range(3)]
        for reader in readers:
            reader.start()

        def reads():
            return sum(reader.outcomes["ok"] for reader in readers)

        self.assertTrue(simlib.wait_until(lambda: reads() >= 30, gl.IO_TIMEOUT, interval=0.01))
        for n in range(RELOADS):
            old, new = (BEFORE, AFTER) if n % 2 == 0 else (AFTER, BEFORE)
            self.rewrite_config(old, new)
            mark = len(self.gateway.text().splitlines())
            self.gateway.signal(signal.SIGHUP)
            applied = self.gateway.wait_line(lambda line: "configuration reloaded" in line, gl.IO_TIMEOUT,
                                             start=mark)
            self.assertIsNotNone(applied, "reload %d not applied:\n%s" % (n, self.gateway.text()))
            self.assertIn("devices replaced: gripper-4", self.gateway.text())
            target = reads() + 5
            self.assertTrue(simlib.wait_until(lambda: reads() >= target, gl.IO_TIMEOUT, interval=0.005),
                            "the readers stalled after reload %d" % n)
        target = reads() + 30
        self.assertTrue(simlib.wait_until(lambda: reads() >= target, gl.IO_TIMEOUT, interval=0.01))
        for reader in readers:
            reader.stop.set()
        for reader in readers:
            reader.join(gl.IO_TIMEOUT)
        outcomes = sum((reader.outcomes for reader in readers), collections.Counter())
        print("%d reloads swapping gripper-4 under three readers: %r" % (RELOADS, dict(outcomes)))
        self.assertEqual(set(outcomes), {"ok"}, "reads failed during the reload storm: %r" % dict(outcomes))


if __name__ == "__main__":
    gl.main()
