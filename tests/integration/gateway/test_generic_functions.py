"""A generic `modbus` device carries what libmodbus' own server and mbusd carry (issue 24
item 10): 0x11 report server ID, 0x16 mask write and 0x17 read/write multiple registers,
through the same block and access checks as FC03/06/16; and a reply from the device
whose length does not fit the request is answered 0x04 at once, never held until the
response timeout, and never counted toward taking the device offline.

The device is libmodbus itself (fb_test_libmodbus_slave: modbus_receive / modbus_reply on
a pseudo-terminal), so the frames are checked by an implementation other than ours."""

import os
import struct
import subprocess
import time

import gatewaylib
from gatewaylib import mbap, read_frame

METER = 20
SLAVE = os.environ.get("FB_LIBMODBUS_SLAVE")

LINE_C = """\
  - name: line-c
    port: {port}
    baud: 115200
    response_timeout: 300ms
    offline_after: 2
    devices:
      - name: meter
        type: modbus
        address: 7
        unit_id: 20
        command_ttl: 2s
        blocks:
          - {{table: holding, address: 0x0000, count: 0x40, writable: true, period: 2s}}
          - {{table: holding, address: 0x0040, count: 0x10, period: 2s}}
          - {{table: holding, address: 0x00F0, count: 4, period: 200ms}}
"""

# Nobody writes the meter's 0x0030-0x003F, with any function code.
RULE = ("  rules:\n    - {units: [20], functions: [6, 16, 22, 23], registers: {from: 0x0030, to: 0x003F},"
        " action: deny}\n")


def read_holding(address, count):
    return struct.pack(">BHH", 3, address, count)


def write_single(address, value):
    return struct.pack(">BHH", 6, address, value)


def mask_write(address, and_mask, or_mask):
    return struct.pack(">BHHH", 0x16, address, and_mask, or_mask)


def read_write(read_address, read_count, write_address, values):
    return struct.pack(">BHHHHB", 0x17, read_address, read_count, write_address, len(values),
                       2 * len(values)) + b"".join(struct.pack(">H", v) for v in values)


def registers(pdu):
    return list(struct.unpack(">%dH" % (pdu[1] // 2), pdu[2:2 + pdu[1]]))


class GenericFunctions(gatewaylib.CellTestCase):

    def setUp(self):
        super().setUp()
        if not SLAVE:
            self.fail("FB_LIBMODBUS_SLAVE is not set (the ctest entry sets it)")

    def start(self):
        # A test peer built for this machine, also in a cross build (CMakeLists.txt).
        slave = subprocess.Popen([SLAVE, self.path("line-c"), "7"], stdout=subprocess.PIPE, text=True)
        self.addCleanup(slave.wait, 5)
        self.addCleanup(slave.kill)
        self.assertEqual(slave.stdout.readline().strip(), "ready")
        self.start_cell(extra_lines=LINE_C.format(port=self.path("line-c")), rules=RULE)
        self.sock = self.raw()
        self.transaction = 0

    def exchange(self, pdu):
        self.transaction += 1
        started = time.monotonic()
        self.sock.sendall(mbap(self.transaction, METER, pdu))
        frame = read_frame(self.sock)
        self.assertIsNotNone(frame, "no answer to %s" % pdu.hex(" "))
        self.assertEqual(frame[0], self.transaction)
        return frame[2], time.monotonic() - started

    def answer(self, pdu):
        return self.exchange(pdu)[0]

    def test_read_write_mask_write_and_server_id_through_the_block_and_access_checks(self):
        self.start()
        # 0x17: the write goes first, then the read (Modbus 6.17), both in the blocks.
        reply = self.answer(read_write(0x000E, 6, 0x0010, [0xAAAA, 0xBBBB]))
        self.assertEqual(reply[0], 0x17, reply.hex(" "))
        self.assertEqual(registers(reply), [0x0E, 0x0F, 0xAAAA, 0xBBBB, 0x12, 0x13])
        self.assertEqual(registers(self.answer(read_holding(0x0010, 2))), [0xAAAA, 0xBBBB])
        # 0x16: (0x0020 AND 0x00F2) OR (0x0025 AND NOT 0x00F2) = 0x0025 (the masks of Modbus 6.16).
        self.assertEqual(self.answer(mask_write(0x0020, 0x00F2, 0x0025)), mask_write(0x0020, 0x00F2, 0x0025))
        self.assertEqual(registers(self.answer(read_holding(0x0020, 1))), [0x0025])
        # 0x11: libmodbus answers with its slave ID, run indicator and "LMB<version>".
        reply = self.answer(bytes([0x11]))
        self.assertEqual(reply[0], 0x11, reply.hex(" "))
        self.assertEqual(reply[1], len(reply) - 2)
        self.assertIn(b"LMB", reply)
        # The same checks as FC03/06/16: a read outside the blocks, a write to the
        # read-only block, and what the rule denies, refused before the line.
        for pdu, code in [(read_write(0x0100, 2, 0x0010, [1]), 0x02),
                          (read_write(0x0000, 2, 0x0042, [1]), self.answer(write_single(0x0042, 1))[1]),
                          (mask_write(0x0042, 0, 1), self.answer(write_single(0x0042, 1))[1]),
                          (mask_write(0x0080, 0, 1), 0x02),
                          (mask_write(0x0031, 0, 1), 0x01),
                          (read_write(0x0000, 1, 0x0030, [1]), 0x01),
                          (bytes([0x11, 0x00]), 0x03)]:
            self.assertEqual(self.answer(pdu), bytes([pdu[0] | 0x80, code]), pdu.hex(" "))
        self.assertEqual(registers(self.answer(read_holding(0x0030, 2))), [0x30, 0x31])

    def test_a_reply_that_does_not_fit_is_answered_at_once_and_the_device_stays_online(self):
        self.start()
        self.assertEqual(registers(self.answer(read_holding(0x0000, 2))), [0, 1])
        # libmodbus answers any read from 0x00F0 with one register: 0x04 at once (well
        # before the 300 ms response timeout), every time.
        for _ in range(6):
            reply, took = self.exchange(read_holding(0x00F0, 4))
            self.assertEqual(reply, bytes([0x83, 0x04]))
            self.assertLess(took, 0.25, "held until the response timeout")
        # Its polls of that block get the same misfit every 200 ms: the device answers,
        # so it is never taken offline (offline_after: 2).
        time.sleep(1.0)
        self.assertEqual(registers(self.answer(read_holding(0x0004, 2))), [4, 5])
        self.assertNotIn("meter", "".join(line for line in self.gateway.text().splitlines(True)
                                          if "offline" in line))


if __name__ == "__main__":
    gatewaylib.main()
