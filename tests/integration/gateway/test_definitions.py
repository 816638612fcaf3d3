"""A device type that is one definition file and no C++ (issue 25): the test writes a
definition in a temporary folder, the gateway finds it through `definitions:`, the
simulator runs the same file, and the device is read, written and alarmed through
Modbus TCP and MQTT: fields in engineering units with units and enum labels, point
checks on TCP writes (min / max after scale, a value written whole), the `write` op
(all or nothing) and the `read` op, and alarms from a bit and from a threshold with
hysteresis. And a built-in type's definition file: an operator's copy takes effect,
and the compiled-in definition stands in once the copy is gone."""

import json
import os
import struct

import gatewaylib
from gatewaylib import json_predicate

PREFIX = "fieldbridge/e2e"
TIMEOUT = 15.0
UNIT = 21

DEFINITION = """\
name: test-meter
description: a meter written by the test
period: 200ms
points:
  - {name: voltage, table: input, address: 0x0000, type: float32, unit: V}
  - {name: energy, table: input, address: 0x0002, type: uint32, word_order: low_first, unit: Wh}
  - {name: status, table: input, address: 0x0004}
  - {name: mode, table: holding, address: 0x0010, writable: true, enum: {0: off, 1: heat, 2: cool}}
  - {name: setpoint, table: holding, address: 0x0011, type: int16, scale: 0.1, unit: degC,
     writable: true, min: 5, max: 30}
  - {name: limit, table: holding, address: 0x0012, type: uint32, writable: true, max: 100000}
  - {name: relay, table: coils, address: 0x0003, writable: true}
alarms:
  - {name: sensor_fault, point: status, bit: 0, severity: error, text: sensor broken}
  - {name: overvoltage, point: voltage, above: 250, hysteresis: 1, severity: critical}
"""

LINE_C = """\
  - name: line-c
    port: {port}
    baud: 115200
    response_timeout: 300ms
    devices:
      - {{name: meter-1, type: test-meter, address: 9, unit_id: 21, max_age: 0ms, command_ttl: 2s}}
"""


def topic(*levels):
    return "/".join((PREFIX,) + levels)


def float_registers(value):
    high, low = struct.unpack(">HH", struct.pack(">f", value))
    return [high, low]


class DefinitionDevice(gatewaylib.CellTestCase):

    def start(self):
        definitions = self.path("devices")
        os.mkdir(definitions)
        with open(os.path.join(definitions, "test-meter.yaml"), "w", encoding="utf-8") as f:
            f.write(DEFINITION)
        self.mqtt_config = gatewaylib.MQTT_CONFIG + "definitions: [%s]\n" % definitions

        def subscribe_first():
            self.sub = self.subscribe(PREFIX + "/#")
        self.commands = 0
        self.start_cell(mqtt=True, before_gateway=subscribe_first,
                        extra_lines=LINE_C.format(port=self.path("line-c")),
                        sim_extra=("--definitions", definitions, "--bus", self.path("line-c") + ":test-meter@9"))

    def sim_set(self, point, value):
        self.control("device line-c@9 set %s %s" % (point, value))

    def wait_state(self, check, start=0):
        found = self.sub.wait_message(topic("meter-1", "state"), json_predicate(check), TIMEOUT, start)
        self.assertIsNotNone(found, "no matching state of meter-1")
        return json.loads(found[1])

    def wait_alarm(self, code, event, start):
        found = self.sub.wait_message(topic("meter-1", "alarm"), json_predicate(
            lambda a: a.get("event") == event and a.get("code") == code), TIMEOUT, start)
        self.assertIsNotNone(found, "no alarm %s %s" % (code, event))
        return json.loads(found[1])

    def command(self, payload, ok=True):
        self.commands += 1
        payload = dict(payload, id="d%d" % self.commands)
        mark = self.sub.mark()
        self.publish(topic("meter-1", "cmd"), json.dumps(payload))
        found = self.sub.wait_message(topic("meter-1", "cmd", "result"),
                                      json_predicate(lambda r: r["id"] == payload["id"]), TIMEOUT, mark)
        self.assertIsNotNone(found, "no result for %r" % payload)
        result = json.loads(found[1])
        self.assertEqual(result["ok"], ok, result)
        return result

    def test_read_write_and_alarms_through_modbus_tcp_and_mqtt(self):
        self.start()
        for point, value in (("voltage", 230.5), ("energy", 123456), ("mode", "heat"), ("setpoint", 21.5)):
            self.sim_set(point, value)
        # MQTT: the fields in engineering units, the units, the enum's label and code.
        state = self.wait_state(lambda s: s["online"] and s["fields"].get("voltage") == 230.5
                                and s["fields"].get("energy") == 123456 and s["fields"].get("setpoint") == 21.5)
        self.assertEqual(state["type"], "test-meter")
        self.assertEqual(state["fields"]["mode"], "heat")
        self.assertEqual(state["fields"]["mode_code"], 1)
        self.assertIs(state["fields"]["relay"], False)
        self.assertEqual(state["units"], {"voltage": "V", "energy": "Wh", "setpoint": "degC"})

        # Modbus TCP: the registers as the device holds them (energy low word first).
        client = self.client()
        self.assertEqual(self.read_input(client, 0x0000, 4, UNIT), float_registers(230.5) + [123456 & 0xFFFF, 123456 >> 16])
        # A register no point names: 0x02, without asking the device.
        self.assert_exception(client.read_input_registers(0x0005, count=1, slave=UNIT), 0x02)
        # Point checks on writes: 25.0 degC is in range, 40.0 is not (0x03); half of a
        # two-register point is refused (0x02); a read-only table cannot be written.
        self.assert_ok(client.write_register(0x0011, 250, slave=UNIT))
        self.assertEqual(self.read_holding(client, 0x0011, 1, UNIT), [250])
        self.assert_exception(client.write_register(0x0011, 400, slave=UNIT), 0x03)
        self.assert_exception(client.write_register(0x0012, 1, slave=UNIT), 0x02)
        self.assert_exception(client.write_registers(0x0012, [0x0001, 0x86A1], slave=UNIT), 0x03)  # 100001 > max
        self.assert_ok(client.write_registers(0x0012, [0x0001, 0x86A0], slave=UNIT))
        self.assertEqual(self.read_holding(client, 0x0010, 4, UNIT), [1, 250, 0x0001, 0x86A0])

        # MQTT write: all or nothing.
        mark = self.sub.mark()
        self.command({"op": "write", "values": {"setpoint": 22.5, "mode": "cool", "relay": True}})
        self.assertEqual(self.read_holding(client, 0x0010, 2, UNIT), [2, 225])
        self.assertEqual(self.assert_ok(client.read_coils(0x0003, count=1, slave=UNIT)).bits[0], True)
        self.wait_state(lambda s: s["fields"].get("mode") == "cool" and s["fields"].get("setpoint") == 22.5
                        and s["fields"].get("relay") is True, mark)
        refused = self.command({"op": "write", "values": {"mode": "off", "setpoint": 99}}, ok=False)
        self.assertEqual(refused["error"], "out_of_range")
        self.assertIn("setpoint", refused["message"])
        self.assertEqual(self.command({"op": "write", "values": {"voltage": 1}}, ok=False)["error"], "invalid_field")
        # Nothing of the refused commands was written.
        self.assertEqual(self.read_holding(client, 0x0010, 2, UNIT), [2, 225])

        # MQTT read: a fresh read, answered with the values.
        self.sim_set("voltage", 231.25)
        result = self.command({"op": "read", "points": ["voltage", "mode"]})
        self.assertEqual(result["values"], {"voltage": 231.25, "mode": "cool", "mode_code": 2})

        # Alarms: a bit, and a threshold with hysteresis; `source` names the point.
        mark = self.sub.mark()
        self.sim_set("status", 1)
        raised = self.wait_alarm("sensor_fault", "raised", mark)
        self.assertEqual((raised["severity"], raised["text"], raised["source"]), ("error", "sensor broken", "point status"))
        self.sim_set("status", 0)
        self.wait_alarm("sensor_fault", "cleared", mark)
        mark = self.sub.mark()
        self.sim_set("voltage", 251)
        self.assertEqual(self.wait_alarm("overvoltage", "raised", mark)["severity"], "critical")
        self.sim_set("voltage", 249.5)  # inside the hysteresis: still raised
        self.wait_state(lambda s: s["fields"].get("voltage") == 249.5, mark)
        self.sim_set("voltage", 248.5)
        cleared = self.wait_alarm("overvoltage", "cleared", mark)
        # Between raised and cleared, no other overvoltage event.
        events = [json.loads(p) for retained, p in self.sub.messages(topic("meter-1", "alarm"), mark) if not retained]
        overvoltage = [e["event"] for e in events if e.get("code") == "overvoltage"]
        self.assertEqual(overvoltage, ["raised", "cleared"], events)
        self.assertEqual(cleared["source"], "point voltage")


SHIPPED = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir,
                                        "config", "devices"))
ABS_ROW = "{name: abs, address: 0x0100, width: 2, access: write, motion: true, min: -8300000, max: 8300000}"


class BuiltInDefinition(gatewaylib.CellTestCase):
    """A built-in type's register map is its definition (docs/devices.md, "Built-in
    types"): an operator's copy of excd203mb.yaml in the definitions: directory narrows
    what clients may write to the EXCD203MB of the cell; with the copy removed, a
    reload brings back the definition compiled into fieldbridge."""

    def test_an_operators_copy_narrows_abs_and_a_reload_without_it_restores_the_compiled_in_map(self):
        definitions = self.path("devices")
        os.mkdir(definitions)
        with open(os.path.join(SHIPPED, "excd203mb.yaml"), encoding="utf-8") as f:
            text = f.read()
        self.assertIn(ABS_ROW, text)
        copy = os.path.join(definitions, "excd203mb.yaml")
        with open(copy, "w", encoding="utf-8") as f:
            f.write(text.replace(ABS_ROW, ABS_ROW.replace("min: -8300000, max: 8300000", "min: 0, max: 100000")))
        self.start_cell(rules="definitions: [%s]\n" % definitions)
        client = self.client()
        stepper = 2
        # abs 100001 (0x000186A1): the shipped range allows it, the site's copy does not.
        self.assert_exception(client.write_registers(0x0100, [0x0001, 0x86A1], slave=stepper), 0x03)
        self.assert_ok(client.write_registers(0x0100, [0x0001, 0x86A0], slave=stepper))
        # The rest of the map as shipped: rabs reads, a hole is 0x02.
        self.assert_ok(client.read_holding_registers(0x0201, count=2, slave=stepper))
        self.assert_exception(client.read_holding_registers(0x003D, count=1, slave=stepper), 0x02)

        os.remove(copy)
        self.reload(timeout=10)
        client = self.client()
        self.wait_value(lambda: client.write_registers(0x0100, [0x0001, 0x86A1], slave=stepper).isError(), False, 5,
                        "abs 100001 accepted with the compiled-in definition")


if __name__ == "__main__":
    gatewaylib.main()
