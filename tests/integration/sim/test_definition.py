"""fieldbridge-sim running a device definition file (docs/simulator.md,
"Definitions"): the shipped worked example (config/devices/example-thermostat.yaml)
on a pseudo-terminal answers exactly its points' registers (02 elsewhere), takes
values by point name in engineering units and by raw register through the control
socket, and keeps what the master writes. A type with no definition, a broken
definition, and a site's variant of a built-in type stop the start with the reason."""

import os
import struct
import subprocess

import simlib
from simlib import rtu, transact

HERE = os.path.dirname(os.path.abspath(__file__))
SHIPPED = os.path.normpath(os.path.join(HERE, os.pardir, os.pardir, os.pardir, "config", "devices"))


def registers(reply):
    """The register values of an FC03/FC04 reply."""
    count = reply[2] // 2
    return list(struct.unpack(">%dH" % count, reply[3:3 + 2 * count]))


class Definition(simlib.SimTestCase):

    def read(self, fd, function, address, count, unit=7):
        reply = transact(fd, rtu("%02X%02X%04X%04X" % (unit, function, address, count)), 5 + 2 * count)
        self.assertTrue(simlib.crc_ok(reply), reply.hex(" "))
        self.assertEqual(reply[:3], bytes([unit, function, 2 * count]), reply.hex(" "))
        return registers(reply)

    def test_shipped_example_on_a_pty(self):
        self.start("--definitions", SHIPPED, "--bus", self.path("line-a") + ":example-thermostat@7",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        # Every point starts at 0; input 0x0000-0x0004 are all points.
        self.assertEqual(self.read(fd, 4, 0x0000, 5), [0, 0, 0, 0, 0])
        # Input 0x0005 is no point: 02, as a real device without the register.
        self.assertEqual(transact(fd, rtu("0704 0000 0006".replace(" ", "")), 5), rtu("078402"))
        # Values by point name, in engineering units.
        for line in ("device 7 set temperature 21.5", "device 7 set heating_seconds 3600",
                     "device 7 set status 1", "device 7 set mode heat", "device 7 set setpoint 21.5",
                     "device 7 set firmware TH-1.2"):
            self.assertEqual(self.control(line), "ok", line)
        self.assertEqual(self.read(fd, 4, 0x0000, 5), [0x41AC, 0x0000, 0, 3600, 1])
        self.assertEqual(self.read(fd, 3, 0x0010, 2), [1, 215])
        self.assertEqual(self.read(fd, 3, 0x0020, 4), [0x5448, 0x2D31, 0x2E32, 0])
        # Raw registers, and the master's writes kept.
        self.assertEqual(self.control("device 7 set-register input 0x0004 0x0003"), "ok")
        self.assertEqual(self.read(fd, 4, 0x0004, 1), [3])
        request = rtu("0710 0011 0001 02 00FA".replace(" ", ""))
        self.assertEqual(transact(fd, request, 8), rtu("071000110001"))
        self.assertEqual(self.read(fd, 3, 0x0011, 1), [250])
        # Refusals say why.
        self.assertIn("outside what a int16 holds", self.control("device 7 set setpoint 5000"))
        self.assertIn("has no point 'humidity'", self.control("device 7 set humidity 40"))

    def test_definition_file_option_and_bad_starts(self):
        definition = self.path("meter-x.yaml")
        with open(definition, "w") as f:
            f.write("name: meter-x\npoints:\n  - {name: kwh, table: input, address: 0x10, type: uint32}\n")
        self.start("--definition", definition, "--bus", self.path("line-a") + ":meter-x@3",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        self.assertEqual(self.control("device 3 set kwh 70000"), "ok")
        self.assertEqual(self.read(fd, 4, 0x0010, 2, unit=3), [1, 4464])

        missing = subprocess.run([simlib.SIM, "--definitions", self.tmp, "--bus", self.path("line-b") + ":nowhere@3"],
                                 capture_output=True, text=True, timeout=20)
        self.assertNotEqual(missing.returncode, 0)
        self.assertIn("no definition nowhere.yaml was found; searched: " + self.tmp + "/", missing.stderr)

        with open(self.path("broken.yaml"), "w") as f:
            f.write("name: broken\npoints:\n  - {name: t, table: coils, address: 0, type: float32}\n")
        broken = subprocess.run([simlib.SIM, "--definitions", self.tmp, "--bus", self.path("line-c") + ":broken@3"],
                                capture_output=True, text=True, timeout=20)
        self.assertNotEqual(broken.returncode, 0)
        self.assertIn(self.path("broken.yaml") + ":3:47: points[0].type: table coils holds single bits",
                      broken.stderr)

        # A site's variant of a built-in type (docs/devices.md, "Built-in types"): the
        # simulator names the built-in model to use instead.
        with open(self.path("excd-slow.yaml"), "w") as f:
            f.write("name: excd-slow\nbehaviour: excd203mb\nregisters: [{name: x, address: 0, access: read}]\n")
        variant = subprocess.run([simlib.SIM, "--definitions", self.tmp, "--bus", self.path("line-d") + ":excd-slow@3"],
                                 capture_output=True, text=True, timeout=20)
        self.assertNotEqual(variant.returncode, 0)
        self.assertIn("is a variant of the built-in type excd203mb (behaviour: excd203mb); simulate it as excd203mb@3",
                      variant.stderr)


if __name__ == "__main__":
    simlib.main()
