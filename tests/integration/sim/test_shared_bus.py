"""The demo cell's line: a HIWIN XEG-C2 at 2, an EXCD203MB at 3 and a WTEC-485 in
ASCII mode at 5 on one simulated RS-485 bus (one pseudo-terminal). Each device
answers the examples of its manual (tests/vectors/vectors.yaml) byte for byte while
the others share the line; a request to an absent address gets no reply; a broadcast
(0 for Modbus and WTEC ASCII, 0xFF for the EXCD203MB) is executed and not answered.

The manuals print the EXCD203MB and WTEC examples for address 1; here they are sent
to 3 and 5 with the address (and so the CRC) changed and every other byte as printed.
The XEG examples are for ID 2 and go out unchanged."""

import os

import simlib
from simlib import h, read_for, read_line, readdress_ascii, readdress_rtu, rtu, transact

NO_REPLY_WAIT = 0.2  # far beyond the simulator's reply time, with or without wire time
WTEC_MOTION_TIMEOUT = 10.0

XEG, EXCD, WTEC = 2, 3, 5


class SharedBus(simlib.SimTestCase):

    def setUp(self):
        super().setUp()
        self.vectors = simlib.load_vectors()

    def example(self, what):
        return simlib.vector(what, self.vectors)

    # ---- one exchange of each kind -------------------------------------------------

    def rtu_example(self, fd, what, address=None):
        """Sends the example's request (re-addressed if @p address) and checks the reply
        byte for byte; returns it."""
        v = self.example(what)
        request, response = h(v["request"]), h(v["response"])
        if address is not None:
            request, response = readdress_rtu(request, address), readdress_rtu(response, address)
        reply = transact(fd, request, len(response))
        self.assertEqual(reply.hex(" "), response.hex(" "), what)
        self.assertEqual(read_for(fd, 0.01), b"", what + ": nothing after the reply")
        return reply

    def ascii_example(self, fd, what, address=WTEC, response=None):
        v = self.example(what)
        request = readdress_ascii(v["request"], address)
        expected = response if response is not None else readdress_ascii(v["response"], address)
        os.write(fd, request)
        reply = read_line(fd)
        self.assertEqual(reply, expected, what)
        return reply

    def ascii(self, fd, body):
        """Any WTEC ASCII request (body without CRC); returns the reply line."""
        os.write(fd, simlib.ascii_frame(body))
        return read_line(fd)

    def read_holding(self, fd, address, register, count):
        reply = transact(fd, rtu("%02X03%04X%04X" % (address, register, count)), 5 + 2 * count)
        self.assertTrue(simlib.crc_ok(reply), reply.hex(" "))
        self.assertEqual(reply[:3], bytes([address, 3, 2 * count]), reply.hex(" "))
        return reply[3:-2]

    def no_reply(self, fd, request, why):
        os.write(fd, request)
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), b"", why)

    def wait_ascii(self, fd, body, expected):
        last = []

        def poll():
            last[:] = [self.ascii(fd, body)]
            return last[0] == expected
        self.assertTrue(simlib.wait_until(poll, WTEC_MOTION_TIMEOUT, 0.05),
                        "%s never answered %r; last %r" % (body, expected, last))

    # ---- the scenario ----------------------------------------------------------------

    def replay(self, *extra):
        self.start("--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                   "--control", self.path("sim.sock"), *extra)
        fd = self.open_port("line-a")

        # Interleaved: each device answers its own examples, the others stay silent.
        self.rtu_example(fd, "write gripper model XEG-32 (0x0A20) to 0x0600, id 2")
        self.ascii_example(fd, "A read firmware version")
        self.rtu_example(fd, "hdir 0x0000=1 (home direction reverse)", EXCD)
        self.rtu_example(fd, "read gripper model 0x0600")
        self.ascii_example(fd, "a enable(1)/release(0) motor")
        self.rtu_example(fd, "solm+ 0x0014 (2 registers) = 800000 = 0x000C3500, high word first", EXCD)
        self.rtu_example(fd, "read firmware 0x0303-0x0306 -> V3.0.1.884")
        self.rtu_example(fd, "read rabs 0x0201 (2 registers) -> 0", EXCD)
        self.rtu_example(fd, "read rin 0x0203 -> 0x000F", EXCD)
        self.rtu_example(fd, "FC06 to nonexistent 0x0611 -> exception 02")
        for what in ("B read homing parameters", "b write homing parameters",
                     "C set peak (grip) current 0x3C", "P read PID", "p write PID",
                     "R read driver parameters", "r write driver parameters",
                     "W read release current and speed", "w write release current and speed",
                     "U save all parameters", "n write gripper parameters",
                     "N read gripper parameters"):
            self.ascii_example(fd, what)
        # save: the manual prints the request without a reply; the device acknowledges.
        save = readdress_rtu(h(self.example(
            "save after switching to Modbus mode, id 1: write 0x0303=0")["request"]), EXCD)
        self.assertEqual(transact(fd, save, 8), rtu("03 10 03 03 00 01"))

        # Examples that need a state, brought about through the control socket.
        self.assertEqual(self.control("device 2 inputs 0x22"), "ok")
        self.rtu_example(fd, "read 8 discrete inputs from 0x0000, id 2; reply 0x22 = HOLD and "
                             "CHK1 on (example bits as printed)")
        self.assertEqual(self.control("device line-a@2 alarm 7"), "ok")
        self.rtu_example(fd, "read exception status FC07 -> 02 emergency stop")
        self.assertEqual(self.control("device 2 clear"), "ok")

        # WTEC homing, a grip action, then a release to the limit: g, d, E and I.
        self.ascii_example(fd, "G reset (homing)")
        self.wait_ascii(fd, ">05g", readdress_ascii(self.example("g query homing state -> 01 done")["response"], WTEC))
        self.ascii_example(fd, "d query in-position state -> 01 reached")
        self.ascii_example(fd, "E gripper action 1 grip (2 release, 3 toggle)")
        self.assertEqual(self.ascii(fd, ">05E2"), simlib.ascii_frame(">05E"))
        running = readdress_ascii(self.example("I read running values")["response"], WTEC)
        self.wait_ascii(fd, ">05I", running)

        # Absent addresses: nobody answers, on either protocol.
        self.no_reply(fd, rtu("09 03 02 01 00 02"), "RTU request to absent ID 9")
        self.no_reply(fd, simlib.ascii_frame(">07A"), "ASCII request to absent address 07")

        # Broadcast 0 (Modbus): the XEG stores the model code, nobody answers.
        self.no_reply(fd, rtu("00 10 06 00 00 01 02 0A 10"), "Modbus broadcast to 0")
        self.assertEqual(self.read_holding(fd, XEG, 0x0600, 1), h("0A 10"))
        self.rtu_example(fd, "write gripper model XEG-32 (0x0A20) to 0x0600, id 2")
        # Broadcast 0xFF (EXCD203MB): variable n01 = 1234 is written, nobody answers.
        self.no_reply(fd, rtu("FF 10 04 01 00 02 04 00 00 04 D2"), "EXCD broadcast to 0xFF")
        self.assertEqual(self.read_holding(fd, EXCD, 0x0401, 2), h("00 00 04 D2"))
        # WTEC ASCII broadcast 00: n acts silently, N at 05 reads it back.
        self.no_reply(fd, simlib.ascii_frame(">00n000012343FFF0A0"), "ASCII n to 00")
        self.assertEqual(self.ascii(fd, ">05N"), simlib.ascii_frame(">05N000012343FFF0A0"))
        # '$' to 00 is the exception: every station answers, from its own address.
        self.ascii_example(fd, "$ read all station numbers (broadcast; every device answers)",
                           address=0, response=simlib.ascii_frame(">05$05"))
        # i: the station number changes and the reply comes from the new one.
        self.ascii_example(fd, "i change station number 01 -> 0A (reply from the new address)",
                           response=simlib.ascii_frame(">0Ai"))
        self.no_reply(fd, simlib.ascii_frame(">05A"), "the old address 05 is gone")
        self.assertEqual(self.ascii(fd, ">00$"), simlib.ascii_frame(">0A$0A"))

        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["crc_errors"], 0)
        self.assertEqual(stats["garbage_bytes"], 0)
        self.assertEqual(stats["collisions"], 0)
        self.assertEqual(stats["unanswered"], 3)   # ID 9, address 07, old address 05
        self.assertEqual(stats["broadcasts"], 5)   # 00 RTU, FF, 00 n, 00 $ twice
        self.assertEqual({a: d["type"] for a, d in stats["devices"].items()},
                         {"2": "hiwin-xeg", "3": "excd203mb", "10": "wtec-ascii"})
        self.assertEqual(stats["devices"]["3"]["replies"], 6)
        return stats

    def test_read_all_stations_as_printed(self):
        # The manual's '$' example verbatim: stations 01 and 02 on one line, both
        # answer the broadcast, one after the other, from their own addresses.
        self.start("--bus", self.path("line-c") + ":wtec-ascii@1,wtec-ascii@2", "--wire-time",
                   "--baud", "19200")
        fd = self.open_port("line-c")
        v = self.example("$ read all station numbers (broadcast; every device answers)")
        os.write(fd, v["request"].encode() + b"\r\n")
        self.assertEqual(read_line(fd), v["response"].encode() + b"\r\n")
        self.assertEqual(read_line(fd), b">02$02A79F\r\n")  # the note's second reply
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), b"")

    def test_demo_line_instant(self):
        self.replay()

    def test_demo_line_with_wire_time(self):
        stats = self.replay("--wire-time", "--baud", "115200", "--turnaround", "1ms")
        self.assertTrue(stats["wire_time"])
        self.assertEqual(stats["timing"]["writes"], stats["replies"])


if __name__ == "__main__":
    simlib.main()
