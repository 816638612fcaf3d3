"""The Huacheng R6 Modbus TCP simulator on loopback (seed 004), from three clients:
- a raw socket replaying the manual's printed request frames (MBAP header included)
  and comparing the replies byte for byte with the printed ones;
- pymodbus (Debian's python3-pymodbus): counter indirection, 32- and 64-bit values,
  the version string, alarm number, move state, axes and world coordinates while the
  robot runs a cycle;
- mbpoll reading one register (references are 1-based unless -0).

Runs under the interpreter that has python3-pymodbus (CMakeLists.txt beside this
file picks Debian's /usr/bin/python3)."""

import socket
import struct
import subprocess
import time

import simlib

try:
    from pymodbus.client import ModbusTcpClient
    from pymodbus.constants import Endian
    from pymodbus.payload import BinaryPayloadDecoder
    PYMODBUS_ERROR = None
except ImportError as e:  # reported by the tests that need it, as a failure
    PYMODBUS_ERROR = e

IO_TIMEOUT = 3.0
CYCLE_TIMEOUT = 15.0  # one cycle is 6 s at 100 % global speed

# Section 3.1-3.3 examples as printed: (request, response), MBAP header included.
PRINTED = [
    ("00 00 00 00 00 06 01 03 00 00 00 01", "00 00 00 00 00 05 01 03 02 00 29"),      # 3.1.1
    ("00 00 00 00 00 06 01 03 00 82 00 01", "00 00 00 00 00 05 01 03 02 00 02"),      # 3.1.3
    ("00 00 00 00 00 06 01 03 00 83 00 04",
     "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 01"),
    ("00 00 00 00 00 0B 01 10 08 83 00 02 04 00 00 00 01",
     "00 00 00 00 00 06 01 10 08 83 00 02"),                                           # 3.1.4
    ("00 00 00 00 00 06 01 03 08 83 00 06",
     "00 00 00 00 00 0f 01 03 0c 00 00 00 01 00 00 00 0a 00 00 00 05"),
    ("00 00 00 00 00 06 01 03 08 89 00 01", "00 00 00 00 00 05 01 03 02 00 03"),      # 3.1.5
    ("00 00 00 00 00 06 01 03 08 8a 00 01", "00 00 00 00 00 05 01 03 02 00 01"),      # 3.1.6
    ("00 00 00 00 00 06 01 03 08 8b 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"),
    ("00 00 00 00 00 06 01 03 08 b3 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"),
    ("00 00 00 00 00 06 01 03 08 db 00 01", "00 00 00 00 00 05 01 03 02 00 06"),      # 3.1.7
    ("00 00 00 00 00 06 01 03 08 dc 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"),  # 3.1.8
    ("00 00 00 00 00 06 01 03 09 1c 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"),  # 3.1.9
    ("00 00 00 00 00 06 01 03 09 5d 00 04",
     "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"),                           # 3.1.11
    ("00 00 00 00 00 06 01 03 09 61 00 04",
     "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"),
    ("00 00 00 00 00 06 01 03 09 65 00 01", "00 00 00 00 00 05 01 03 02 00 01"),      # 3.1.12
    ("00 00 00 00 00 06 01 03 09 66 00 01", "00 00 00 00 00 05 01 03 02 00 00"),      # 3.1.13
    ("00 00 00 00 00 06 01 03 09 86 00 01", "00 00 00 00 00 05 01 03 02 00 00"),      # 3.1.14
    ("00 00 00 00 00 06 01 06 4e 20 00 01", "00 00 00 00 00 06 01 06 4e 20 00 01"),   # 3.2.1
    ("00 00 00 00 00 06 01 06 4e e8 00 64", "00 00 00 00 00 06 01 06 4e e8 00 64"),   # 3.2.2
    ("00 00 00 00 00 0B 01 10 08 b3 00 02 04 00 00 00 01",
     "00 00 00 00 00 06 01 10 08 b3 00 02"),                                           # 3.3.1
    ("00 00 00 00 00 13 01 10 4e 52 00 06 0c 00 00 00 01 00 00 00 00 00 00 00 08",
     "00 00 00 00 00 06 01 10 4e 52 00 06"),                                           # 3.3.2
    ("00 00 00 00 00 0d 01 10 4e 58 00 03 06 00 00 00 01 00 01",
     "00 00 00 00 00 06 01 10 4e 58 00 03"),                                           # 3.3.3
    ("00 00 00 00 00 0b 01 10 4f 4c 00 02 04 00 00 00 64",
     "00 00 00 00 00 06 01 10 4f 4c 00 02"),                                           # 3.3.4
]
# 3.1.10 needs alarm 805, 3.1.15 a running robot: sent after `r6 alarm 805` / `r6 start`.
ALARM_805 = ("00 00 00 00 00 06 01 03 09 5c 00 01", "00 00 00 00 00 05 01 03 02 03 25")
MOVING = ("00 00 00 00 00 06 01 03 09 a6 00 01", "00 00 00 00 00 05 01 03 02 00 01")


def recv_exactly(sock, count):
    data = b""
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            raise AssertionError("the R6 simulator closed the connection after %r" % data)
        data += chunk
    return data


def exchange(sock, request):
    sock.sendall(request)
    header = recv_exactly(sock, 6)
    length = struct.unpack(">H", header[4:6])[0]
    return header + recv_exactly(sock, length)


class R6Tcp(simlib.SimTestCase):

    def start_r6(self, *extra):
        self.start("--r6", "127.0.0.1:0", "--control", self.path("sim.sock"), *extra)
        listen = self.stats()["r6"]["listen"]
        host, _, port = listen.rpartition(":")
        self.assertEqual(host, "127.0.0.1")
        self.port = int(port)
        self.assertGreater(self.port, 0)
        return self.port

    def ok(self, line):
        self.assertEqual(self.control(line), "ok", line)

    def test_printed_frames_byte_for_byte(self):
        port = self.start_r6()
        with socket.create_connection(("127.0.0.1", port), timeout=IO_TIMEOUT) as s:
            for request, response in PRINTED:
                self.assertEqual(exchange(s, simlib.h(request)).hex(" "),
                                 simlib.h(response).hex(" "), "request " + request)
            self.ok("r6 alarm 805")
            self.assertEqual(exchange(s, simlib.h(ALARM_805[0])), simlib.h(ALARM_805[1]))
            self.ok("r6 clear")
            self.ok("r6 start")
            self.assertEqual(exchange(s, simlib.h(MOVING[0])), simlib.h(MOVING[1]))
            # The transaction id and unit id of each request come back unchanged.
            reply = exchange(s, simlib.h("12 34 00 00 00 06 07 03 08 db 00 01"))
            self.assertEqual(reply, simlib.h("12 34 00 00 00 05 07 03 02 00 06"))
            # Exceptions: half an axis (02), an unknown function (01).
            self.assertEqual(exchange(s, simlib.h("00 01 00 00 00 06 01 03 08 dd 00 01")),
                             simlib.h("00 01 00 00 00 03 01 83 02"))
            self.assertEqual(exchange(s, simlib.h("00 02 00 00 00 02 01 2b")),
                             simlib.h("00 02 00 00 00 03 01 ab 01"))
        r6 = self.stats()["r6"]
        self.assertEqual(r6["requests"], len(PRINTED) + 5)
        self.assertEqual(r6["exceptions"], 2)
        self.assertEqual(r6["malformed"], 0)

    def test_unit_filter(self):
        port = self.start_r6("--r6-unit", "1")
        with socket.create_connection(("127.0.0.1", port), timeout=IO_TIMEOUT) as s:
            self.assertEqual(exchange(s, simlib.h("00 05 00 00 00 06 01 03 08 db 00 01")),
                             simlib.h("00 05 00 00 00 05 01 03 02 00 06"))
            self.assertEqual(exchange(s, simlib.h("00 06 00 00 00 06 02 03 08 db 00 01")),
                             simlib.h("00 06 00 00 00 03 02 83 0b"))
        self.assertEqual(self.stats()["r6"]["unit_rejected"], 1)

    # ---- pymodbus -------------------------------------------------------------------

    def client(self, port):
        if PYMODBUS_ERROR is not None:
            self.fail("pymodbus is not importable (%s): install python3-pymodbus and "
                      "python3-serial-asyncio (deploy/install-deps.sh) and run this test "
                      "with Debian's python3" % PYMODBUS_ERROR)
        client = ModbusTcpClient("127.0.0.1", port=port, timeout=IO_TIMEOUT, retries=0)
        self.assertTrue(client.connect(), "pymodbus could not connect to 127.0.0.1:%d" % port)
        self.addCleanup(client.close)
        return client

    def regs(self, client, address, count, unit=1):
        rr = client.read_holding_registers(address, count=count, slave=unit)
        self.assertFalse(rr.isError(), "read 0x%04X x%d: %s" % (address, count, rr))
        return rr.registers

    def decoder(self, registers):
        # The R6 sends 32- and 64-bit values high word first, big-endian bytes.
        # Endian.Big in pymodbus 3.0 (Debian 12), Endian.BIG in 3.8 (Debian 13).
        big = Endian.BIG if hasattr(Endian, "BIG") else Endian.Big
        return BinaryPayloadDecoder.fromRegisters(registers, byteorder=big, wordorder=big)

    def test_pymodbus_reads_the_running_robot(self):
        port = self.start_r6()
        client = self.client(port)
        # Version: length, then the string (two characters a register).
        self.assertEqual(self.regs(client, 0x0000, 1), [0x29])
        text = self.decoder(self.regs(client, 0x0001, 21)).decode_string(42)
        self.assertEqual(text.rstrip(b"\0").decode(), "AM8-QC-RXE-7.8.02-bate7_FAKE_TGF_ENCODER")
        # Counters: the list of IDs (32-bit), then the indirection: select ID 1 with
        # FC10 on 0x0883, read ID / target / current from 0x0883.
        self.assertEqual(self.regs(client, 0x0082, 1), [2])
        ids = self.decoder(self.regs(client, 0x0083, 4))
        self.assertEqual([ids.decode_32bit_uint(), ids.decode_32bit_uint()], [0, 1])
        wr = client.write_registers(0x0883, [0, 1], slave=1)
        self.assertFalse(wr.isError(), wr)
        counter = self.decoder(self.regs(client, 0x0883, 6))
        self.assertEqual([counter.decode_32bit_uint() for _ in range(3)], [1, 10, 5])
        # Counter modify (0x4E52: ID, target, current) shows through the indirection.
        wr = client.write_registers(0x4E52, [0, 1, 0, 0, 0, 8], slave=1)
        self.assertFalse(wr.isError(), wr)
        self.assertEqual(self.regs(client, 0x0887, 2), [0, 8])
        # Alarm number (3.1.10): 805; start is refused while it is set.
        self.ok("r6 alarm 805")
        self.assertEqual(self.regs(client, 0x095C, 1), [805])
        self.assertTrue(self.control("r6 start").startswith("error: "))
        self.ok("r6 clear")
        self.assertEqual(self.regs(client, 0x095C, 1), [0])

        # Start through the start-button command 0x4E23: mode 2, move state 1.
        self.assertEqual(self.regs(client, 0x09A6, 1), [0])
        t_sent = time.monotonic()
        wr = client.write_register(0x4E23, 1, slave=1)
        t_acked = time.monotonic()
        self.assertFalse(wr.isError(), wr)
        self.assertEqual(self.regs(client, 0x0889, 1), [2])
        self.assertEqual(self.regs(client, 0x09A6, 1), [1])
        # Axes: 6, signed 32-bit x1000; axis i sweeps 0..(30+10 i) deg in phase with
        # axis 0, which moves at 10 deg/s; world coordinates equal the axes.
        self.assertEqual(self.regs(client, 0x08DB, 1), [6])
        # Until axis 0 has moved 3 deg (0.3 s at 10 deg/s: large against the rounding
        # of the ratios below); the bounds are computed from the times measured here.
        moved = simlib.wait_until(
            lambda: self.decoder(self.regs(client, 0x08DC, 2)).decode_32bit_int() >= 3000, IO_TIMEOUT)
        self.assertTrue(moved, "axis 0 did not move within %.0f s of the start" % IO_TIMEOUT)
        t0 = time.monotonic()
        d = self.decoder(self.regs(client, 0x08DC, 12))
        t1 = time.monotonic()
        axes = [d.decode_32bit_int() for _ in range(6)]
        self.assertTrue((t0 - t_acked) * 10000 - 1 <= axes[0] <= (t1 - t_sent) * 10000 + 1,
                        "axis 0 at %d after %.3f-%.3f s" % (axes[0], t0 - t_sent, t1 - t_sent))
        self.assertEqual(axes, [axes[0] * (30 + 10 * i) // 30 for i in range(6)])
        world = self.decoder(self.regs(client, 0x091C, 12))
        world = [world.decode_32bit_int() for _ in range(6)]
        self.assertEqual(world, [world[0] * (30 + 10 * i) // 30 for i in range(6)])
        self.assertGreaterEqual(world[0], axes[0])  # read later, still rising
        # Torque and speed are not 0 while moving.
        self.assertTrue(all(v > 0 for v in self.regs(client, 0x0966, 6)))
        # Current cycle time (64-bit ms) grows; after one sweep of axis 0 (6 s) the
        # last cycle time is 6000 ms and counter 0 has counted the cycle.
        cycle = self.decoder(self.regs(client, 0x095D, 4)).decode_64bit_uint()
        self.assertGreater(cycle, 0)
        client.write_registers(0x0883, [0, 0], slave=1)
        start_count = self.decoder(self.regs(client, 0x0887, 2)).decode_32bit_uint()
        done = simlib.wait_until(
            lambda: self.decoder(self.regs(client, 0x0961, 4)).decode_64bit_uint() != 0,
            CYCLE_TIMEOUT, 0.1)
        self.assertTrue(done, "no cycle completed within %.0f s" % CYCLE_TIMEOUT)
        self.assertEqual(self.decoder(self.regs(client, 0x0961, 4)).decode_64bit_uint(), 6000)
        self.assertEqual(self.decoder(self.regs(client, 0x0887, 2)).decode_32bit_uint(), start_count + 1)
        # Stop (0x4E20): move state 0, torque back to 0.
        self.assertFalse(client.write_register(0x4E20, 1, slave=1).isError())
        self.assertEqual(self.regs(client, 0x09A6, 1), [0])
        self.assertEqual(self.regs(client, 0x0966, 1), [0])
        # Eight axes on demand.
        self.ok("r6 axes 8")
        self.assertEqual(self.regs(client, 0x08DB, 1), [8])
        self.assertEqual(len(self.regs(client, 0x08DC, 16)), 16)

    # ---- mbpoll --------------------------------------------------------------------

    def mbpoll(self, port, *args):
        run = subprocess.run(["mbpoll", "-m", "tcp", "-p", str(port), *args, "-1", "127.0.0.1"],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=10,
                             stdin=subprocess.DEVNULL)
        out = run.stdout.decode(errors="replace")
        self.assertEqual(run.returncode, 0, out)
        return out

    def test_mbpoll_reads_one_register(self):
        port = self.start_r6()
        self.ok("r6 alarm 805")
        # Alarm number 0x095C = 2396 (PDU address): reference 2397 1-based, 2396 with -0.
        out = self.mbpoll(port, "-a", "1", "-r", "2397", "-c", "1")
        self.assertIn("[2397]: \t805", out)
        out = self.mbpoll(port, "-a", "1", "-0", "-r", "2396", "-c", "1")
        self.assertIn("[2396]: \t805", out)
        # The axis count, as an input register (FC04 reads the same map).
        out = self.mbpoll(port, "-a", "1", "-t", "3", "-r", "2268", "-c", "1")
        self.assertIn("[2268]: \t6", out)


if __name__ == "__main__":
    simlib.main()
