"""WTEC-485 in Modbus-RTU mode on its own pseudo-terminal: every RTU example of the
manual (seed 003 part 2, tests/vectors/vectors.yaml) byte for byte, in an order that
works on a real gripper (initialize before a position, e-stop last but one, the ID
change last). Then the same gripper scenario driven through the RTU face on one bus
and the ASCII face on another: both report the same state (init state, grip state,
position) at each step."""

import os

import simlib
from simlib import h, read_for, read_line, rtu, transact

MOTION_TIMEOUT = 10.0
STROKE = 20000  # counts, the simulator's default --wtec-stroke


class WtecRtu(simlib.SimTestCase):

    def setUp(self):
        super().setUp()
        self.vectors = simlib.load_vectors()

    def example(self, fd, what):
        v = simlib.vector(what, self.vectors)
        self.assertEqual(v["protocol"], "modbus-rtu")
        response = h(v["response"])
        reply = transact(fd, h(v["request"]), len(response))
        self.assertEqual(reply.hex(" "), response.hex(" "), what)
        self.assertEqual(read_for(fd, 0.01), b"", what + ": nothing after the reply")

    def example_read(self, fd, what, value):
        """An example the manual prints with 'xx xx' for the data: the request as
        printed, the reply built from the value the gripper must hold."""
        v = simlib.vector(what, self.vectors)
        self.assertIsNone(v["response"])
        request = h(v["request"])
        expected = rtu("%02X0302%04X" % (request[0], value))
        self.assertEqual(transact(fd, request, 7).hex(" "), expected.hex(" "), what)

    def reg(self, fd, register, unit=1):
        reply = transact(fd, rtu("%02X03%04X0001" % (unit, register)), 7)
        self.assertTrue(simlib.crc_ok(reply) and reply[:3] == bytes([unit, 3, 2]), reply.hex(" "))
        return reply[3] << 8 | reply[4]

    def write(self, fd, register, value, unit=1):
        request = rtu("%02X06%04X%04X" % (unit, register, value))
        self.assertEqual(transact(fd, request, 8), request)

    def wait_reg(self, fd, register, value):
        last = []

        def poll():
            last[:] = [self.reg(fd, register)]
            return last[0] == value
        self.assertTrue(simlib.wait_until(poll, MOTION_TIMEOUT, 0.02),
                        "0x%04X never read %d; last %s" % (register, value, last))

    def test_manual_examples_in_working_order(self):
        self.start("--bus", self.path("line-b") + ":wtec-rtu@1", "--control", self.path("sim.sock"))
        fd = self.open_port("line-b")
        self.example(fd, "read init state 0x0200 -> 0 not initialized")
        self.example(fd, "read instant position 0x0204")
        self.example(fd, "initialize (home) 0x0100=1")
        self.wait_reg(fd, 0x0200, 1)
        self.assertEqual(self.reg(fd, 0x0202), 1)
        self.example(fd, "force 0x0103=80%")
        # Force is the N max (grip) current over R's max current 0x3F: 80 % sets
        # round(50.4) = 50, which reads round(5000 / 63) = 79 % (docs/registers.md).
        self.example_read(fd, "read force 0x0103", 79)
        self.example(fd, "force 0x0103=100%")
        self.example(fd, "position 0x0105=50")
        self.example_read(fd, "read set position 0x0105", 50)
        self.wait_reg(fd, 0x0202, 1)
        self.assertEqual(self.reg(fd, 0x0204), 50)
        self.example(fd, "speed 0x0104=50%")
        self.example_read(fd, "read speed 0x0104", 50)
        # The grip-state example reads 2: an object 30 % wide, close fully.
        self.assertEqual(self.control("device 1 object 30"), "ok")
        self.write(fd, 0x0105, 100)
        self.wait_reg(fd, 0x0202, 2)
        self.example(fd, "read grip state 0x0202 -> 2 object gripped")
        self.assertEqual(self.reg(fd, 0x0204), 70)
        self.example(fd, "init direction 0x0300=1 (open)")
        self.example(fd, "save to flash 0x0302=1")
        self.example(fd, "emergency stop 0x0102=1")
        self.assertEqual(self.reg(fd, 0x0202), 11)  # motor released
        self.assertEqual(transact(fd, rtu("01 06 01 05 00 0A"), 5), rtu("01 86 04"))
        self.example(fd, "set device id 0x0303=5 (reply comes from the new id 5)")
        os.write(fd, rtu("01 03 02 00 00 01"))
        self.assertEqual(read_for(fd, 0.2), b"", "ID 1 is gone")
        self.assertEqual(self.reg(fd, 0x0303, unit=5), 5)
        stats = self.stats()["buses"]["line-b"]
        self.assertEqual(stats["unanswered"], 1)
        self.assertEqual(stats["crc_errors"], 0)

    # ---- one gripper, two faces -------------------------------------------------------

    def ascii(self, fd, body):
        os.write(fd, simlib.ascii_frame(body))
        reply = read_line(fd)
        self.assertTrue(reply.startswith(body[:4].encode()) and reply.endswith(b"\r\n"),
                        "%s -> %r" % (body, reply))
        text = reply[:-2].decode()
        self.assertEqual(simlib.ascii_frame(text[:-4]), reply, "reply CRC")
        return text[4:-4]  # the data

    def rtu_view(self, fd):
        return (self.reg(fd, 0x0200), self.reg(fd, 0x0202), self.reg(fd, 0x0204))

    def ascii_view(self, fd):
        """The ASCII face's state in the uniform register view: g -> 0x0200,
        d -> 0x0202 (05 released to the limit and 06 closed to the limit read 1,
        0x11 reads 11), I position -> 0x0204 percent of the stroke."""
        g = int(self.ascii(fd, ">01g"), 16)
        d = int(self.ascii(fd, ">01d"), 16)
        running = self.ascii(fd, ">01I")
        position = int(running[:8], 16)
        if position >= 1 << 31:
            position -= 1 << 32
        grip = {0x00: 0, 0x01: 1, 0x02: 2, 0x05: 1, 0x06: 1, 0x11: 11}[d]
        percent = min(max((position * 100 + STROKE // 2) // STROKE, 0), 100)
        return (g, grip, percent)

    def both(self, rtu_fd, ascii_fd, expected, step):
        """Waits (bounded) until both faces show @p expected."""
        seen = []

        def poll():
            seen[:] = [self.rtu_view(rtu_fd), self.ascii_view(ascii_fd)]
            return seen[0] == seen[1] == expected
        self.assertTrue(simlib.wait_until(poll, MOTION_TIMEOUT, 0.05),
                        "%s: expected %s from both faces, RTU %s ASCII %s"
                        % (step, expected, *(seen or [None, None])))

    def test_rtu_and_ascii_faces_show_the_same_gripper(self):
        self.start("--bus", self.path("line-b") + ":wtec-rtu@1",
                   "--bus", self.path("line-c") + ":wtec-ascii@1", "--control", self.path("sim.sock"))
        rtu_fd = self.open_port("line-b")
        ascii_fd = self.open_port("line-c")
        self.both(rtu_fd, ascii_fd, (0, 11, 0), "power-up")
        # Initialize: 0x0100 = 1 / G (the reply of G is the request).
        self.write(rtu_fd, 0x0100, 1)
        self.assertEqual(self.ascii(ascii_fd, ">01G"), "")
        self.both(rtu_fd, ascii_fd, (1, 1, 0), "homed")
        # Position 50 %: 0x0105 = 50 / D 10000 counts.
        self.write(rtu_fd, 0x0105, 50)
        self.assertEqual(self.ascii(ascii_fd, ">01D%08X" % (STROKE // 2)), "")
        self.both(rtu_fd, ascii_fd, (1, 1, 50), "at 50 %")
        # An object 30 % wide, close fully: 0x0105 = 100 / E1 -> gripped at 70 %.
        self.assertEqual(self.control("device line-b@1 object 30"), "ok")
        self.assertEqual(self.control("device line-c@1 object 30"), "ok")
        self.write(rtu_fd, 0x0105, 100)
        self.assertEqual(self.ascii(ascii_fd, ">01E1"), "")
        self.both(rtu_fd, ascii_fd, (1, 2, 70), "gripped")
        # E-stop on both grippers: motor released (11), position kept.
        self.write(rtu_fd, 0x0102, 1)
        self.assertEqual(self.control("device line-c@1 estop"), "ok")
        self.both(rtu_fd, ascii_fd, (1, 11, 70), "e-stopped")


if __name__ == "__main__":
    simlib.main()
