"""Sparkplug B edge node end to end (issue 28, part C): the real gateway in front of the
simulated cell, a private mosquitto (two for the primary host's walk) and a test host
(sparkplug_host.py: mosquitto_sub / mosquitto_pub and the tests' own decoder,
tests/support/sparkplug_decode.py). The JSON bridge (`mqtt:`) runs beside it, so the
DBIRTH values are checked against the JSON state of the same device.

In the order of the brief (each class is one part; a part the gateway lacks can be
left out by its class name on the command line):
  Births          NBIRTH / DBIRTH contents, seq continuity, DDATA on change only, NDATA
  Rebirth         NCMD Node Control/Rebirth: same bdSeq, seq 0, every DBIRTH again
  CommandsAccepted, CommandsRefused   DCMD writes (WTEC metrics, XEG Commands/move)
  Deaths          clean stop NDEATH, SIGKILL will, bdSeq kept in state_dir
  DeviceOffline   dead device / unplugged line -> DDEATH, back -> DBIRTH
  PrimaryHost     births wait for STATE online; offline walks to the next server; a
                  malformed STATE is ignored, logged escaped
  OfflineBuffer   data made while the host is offline replayed as historical
  Reload          SIGHUP: a device removed, added or redefined is born again alone; a
                  line removed re-births the node
  CommandFlood    9000 DCMDs at once: bounded memory, Modbus TCP keeps answering"""

import os
import signal
import subprocess
import threading
import time

import gatewaylib
import simlib
import sparkplug_host
from emulation import target_command
from gatewaylib import json_predicate
from sparkplug_host import NODE_MESSAGES, NodeView, SparkplugSubscriber, command_payload, seq_problems, state_payload

PREFIX = "fieldbridge/e2e"
GROUP, EDGE, HOST = "cell", "gw1", "scada"
# docs/configuration.md, sparkplug.client_id: fieldbridge-<gateway id>-sparkplug.
CLIENT_ID = "fieldbridge-e2e-sparkplug"
STATE_TOPIC = "spBv1.0/STATE/" + HOST
TIMEOUT = 15.0
MOTION_TIMEOUT = 30.0
NDATA_PERIOD = 5.0  # node metrics: NDATA at most every 5 s
DEVICES = ("gripper-1", "stepper-1", "gripper-2", "gripper-3")
LINES = ("line-a", "line-b")
# docs/mqtt.md, "Decoded fields per device type": wtec-rtu.
WTEC_RTU_FIELDS = {"init_state", "init_state_code", "grip_state", "grip_state_code", "position_pct", "target_pct",
                   "force_pct", "speed_pct", "estop", "init_direction", "saved", "device_id"}
WTEC_WRITABLE = {"force_pct", "speed_pct", "target_pct"}
JSON_TYPES = {bool: "Boolean", int: "Int64", float: "Double", str: "String"}
STRING_UNIT = lambda unit: {"type": "String", "value": unit}  # noqa: E731
WRITABLE = {"type": "Boolean", "value": True}


def spb_topic(kind, device=None):
    return "/".join(["spBv1.0", GROUP, kind, EDGE] + ([device] if device else []))


def json_topic(device):
    return "%s/%s/state" % (PREFIX, device)


def sparkplug_section(state_dir, servers, primary=False):
    """The `sparkplug:` section; each server is a port or the `{mqtt_port}` that
    start_cell() formats."""
    return ("sparkplug:\n"
            "  servers: [%s]\n"
            "  group_id: %s\n"
            "  edge_node_id: %s\n"
            "%s"
            "  aliases: true\n"
            "  state_dir: %s\n"
            "  keep_alive: 5s\n"
            "  offline_buffer: {{max_messages: 1000, max_bytes: 1048576}}\n"
            % (", ".join('"tcp://127.0.0.1:%s"' % port for port in servers), GROUP, EDGE,
               "  primary_host_id: %s\n" % HOST if primary else "", state_dir))


def metric_names(message):
    return {m["name"] for m in message.metrics}


def field_names(message):
    """A DBIRTH's metrics that show JSON state fields (not the Commands/ folder)."""
    return {m["name"] for m in message.metrics if not m["name"].startswith("Commands/")}


class SparkplugCell(gatewaylib.CellTestCase):

    def setUp(self):
        super().setUp()
        self.state_dir = self.path("spb-state")
        os.mkdir(self.state_dir)
        self.broker_b = None

    # -- starting --------------------------------------------------------------------

    def start(self, primary=False, second_broker=False, r6=False, seed_bdseq=None, before_gateway=None,
              extra_config="", **cell):
        """The cell with the JSON bridge and the Sparkplug node; self.spb (and self.spb_b
        on the second broker) subscribed to spBv1.0/# and self.json to the JSON states
        before the gateway starts. extra_config: more top-level configuration (e.g.
        `definitions:`); cell: more of start_cell()'s arguments (extra_lines, sim_extra)."""
        if seed_bdseq is not None:
            with open(os.path.join(self.state_dir, "sparkplug-bdseq"), "w", encoding="utf-8") as f:
                f.write("%d\n" % seed_bdseq)
        servers = ["{mqtt_port}"]
        if second_broker:
            self.port_b = gatewaylib.free_port()
            servers.append(str(self.port_b))
        self.mqtt_config = (gatewaylib.MQTT_CONFIG + sparkplug_section(self.state_dir, servers, primary)
                            + extra_config.replace("{", "{{").replace("}", "}}"))

        def first():
            self.spb = self.spb_subscribe(self.broker, self.mqtt_port, "spBv1.0/#")
            self.json = self.subscribe(PREFIX + "/+/state")
            if second_broker:
                self.start_broker_b()
                self.spb_b = self.spb_subscribe(self.broker_b, self.port_b, "spBv1.0/#")
            if before_gateway is not None:
                before_gateway()
        self.start_cell(mqtt=True, r6=r6, before_gateway=first, **cell)

    def start_broker_b(self):
        conf = self.path("mosquitto-b.conf")
        with open(conf, "w", encoding="utf-8") as f:
            f.write("listener %d 127.0.0.1\nallow_anonymous true\npersistence false\n%s"
                    % (self.port_b, gatewaylib.BROKER_LOG_TYPES))
        self.broker_b = gatewaylib.Process("mosquitto-b", ["mosquitto", "-c", conf], self.path("mosquitto-b.log"))
        self.processes.append(self.broker_b)
        if not gatewaylib.wait_port(self.port_b, gatewaylib.START_TIMEOUT, self.broker_b.running):
            self.fail("the second mosquitto did not listen on %d:\n%s" % (self.port_b, self.broker_b.text()))

    def spb_subscribe(self, broker, port, *topics):
        """A host subscriber (binary payloads in hex), in place once the broker logged it."""
        self._subscribers += 1
        client_id = "fb-spb-host-%d" % self._subscribers
        command = ["mosquitto_sub", "-h", "127.0.0.1", "-p", str(port), "-q", "1", "-i", client_id,
                   "-F", SparkplugSubscriber.FORMAT]
        for topic in topics:
            command += ["-t", topic]
        mark = broker.mark()
        sub = SparkplugSubscriber("Sparkplug host %s on port %d" % (client_id, port), command,
                                  self.path("spb-sub-%d.log" % self._subscribers),
                                  stdout_lines=True)
        self.processes.append(sub)
        suffix = " %s 1 %s" % (client_id, topics[-1])
        if broker.wait_line(lambda line: line.endswith(suffix), gatewaylib.START_TIMEOUT, mark) is None:
            self.fail("mosquitto did not log the subscription of %s:\n%s" % (client_id, broker.text()))
        return sub

    # -- the host's publications -----------------------------------------------------

    def publish_bytes(self, topic, data, port=None, retain=False, qos=1):
        command = ["mosquitto_pub", "-h", "127.0.0.1", "-p", str(port or self.mqtt_port), "-q", str(qos),
                   "-t", topic, "-s"] + (["-r"] if retain else [])
        done = subprocess.run(command, input=data if isinstance(data, bytes) else data.encode(),
                              capture_output=True, timeout=gatewaylib.IO_TIMEOUT)
        self.assertEqual(done.returncode, 0, done.stderr)

    def dcmd(self, device, metrics, port=None):
        self.publish_bytes(spb_topic("DCMD", device), command_payload(metrics), port)

    def ncmd(self, metrics, port=None):
        self.publish_bytes(spb_topic("NCMD"), command_payload(metrics), port)

    def host_state(self, online, timestamp, port=None):
        """The primary host's retained STATE (QoS 1)."""
        self.publish_bytes(STATE_TOPIC, state_payload(online, timestamp), port, retain=True)

    # -- waiting for the node ----------------------------------------------------------

    def wait_births(self, sub=None, start=0, devices=DEVICES, timeout=TIMEOUT):
        """The first NBIRTH from @p start on and the first DBIRTH of each device after it."""
        sub = sub or self.spb
        nbirth = sub.wait_kind("NBIRTH", timeout, start)
        self.assertIsNotNone(nbirth, "no NBIRTH within %.0f s; the host saw:\n%s" % (timeout, sub.dump(start)))
        births = {}
        for device in devices:
            found = sub.wait_kind("DBIRTH", timeout, nbirth.index + 1, device=device)
            self.assertIsNotNone(found, "no DBIRTH of %s after the NBIRTH; the host saw:\n%s"
                                 % (device, sub.dump(nbirth.index)))
            births[device] = found
        return nbirth, births

    def wait_dbirth_with(self, device, fields, start=0, sub=None, timeout=TIMEOUT):
        """The first DBIRTH of @p device from @p start on whose metrics cover @p fields
        (a field read in the slow poll may come after the first birth, with a new one)."""
        sub = sub or self.spb
        found = sub.wait(lambda m: m.kind == "DBIRTH" and m.device == device and fields <= metric_names(m),
                         timeout, start)
        self.assertIsNotNone(found, "no DBIRTH of %s with %s; births seen:\n%s"
                             % (device, sorted(fields), "\n".join("%s: %s" % (m.device, sorted(metric_names(m)))
                                                                 for m in sub.messages(start, kind="DBIRTH"))))
        return found

    def wait_json(self, device, check, start=0, timeout=TIMEOUT):
        found = self.json.wait_message(json_topic(device), json_predicate(check), timeout, start)
        self.assertIsNotNone(found, "no matching JSON state of %s; last: %s"
                             % (device, (self.json.messages(json_topic(device)) or [None])[-1]))
        return gatewaylib.json.loads(found[1])

    def wait_view_matches_json(self, device, timeout=TIMEOUT):
        """Waits until the host's view of @p device (its DBIRTH, then DDATA by alias)
        holds the values of the device's latest JSON state (a birth may carry null for
        a field not read yet, a DDATA fills it in); returns (JSON state, view values)."""
        last = {}

        def matches():
            states = self.json.messages(json_topic(device))
            if not states:
                return False
            last["state"] = gatewaylib.json.loads(states[-1][1])
            last["view"] = NodeView.of(self.spb.messages()).devices.get(device, {})
            return all(last["view"].get(field, KeyError) == value for field, value in last["state"]["fields"].items())
        if not simlib.wait_until(matches, timeout, interval=0.1):
            state, view = last.get("state", {}), last.get("view", {})
            differ = {field: (value, view.get(field, "absent"))
                      for field, value in state.get("fields", {}).items() if view.get(field, KeyError) != value}
            self.fail("the host's view of %s never matched its JSON state; field: (JSON, Sparkplug): %s"
                      % (device, differ))
        return last["state"], last["view"]

    def wait_node_metric(self, name, check, start, timeout, sub=None):
        """The node metric @p name as the host sees it (NBIRTH, then NDATA by alias) once
        @p check holds; fails with the values seen."""
        sub = sub or self.spb
        seen = []

        def current():
            view = NodeView.of(sub.messages(start))
            value = view.node.get(name, KeyError)
            if not seen or seen[-1] != value:
                seen.append(value)
            return value is not KeyError and check(value)
        self.assertTrue(simlib.wait_until(current, timeout, interval=0.2),
                        "node metric %r never satisfied the check; values seen: %r" % (name, seen))
        return NodeView.of(sub.messages(start)).node[name]

    def ddata_with(self, device, alias, value, start, timeout=TIMEOUT, sub=None):
        """The first DDATA of @p device from @p start on carrying @p alias = @p value."""
        sub = sub or self.spb
        found = sub.wait(lambda m: m.kind == "DDATA" and m.device == device and any(
            x["alias"] == alias and x["value"] == value for x in m.metrics), timeout, start)
        self.assertIsNotNone(found, "no DDATA of %s with alias %s = %r; the host saw:\n%s"
                             % (device, alias, value, sub.dump(start)))
        return found

    def assert_seq(self, sub=None, start=0):
        problems = seq_problems((sub or self.spb).messages(start))
        self.assertFalse(problems, "seq rules broken (%d times):\n%s" % (len(problems), "\n".join(problems)))

    def bdseq_file(self):
        with open(os.path.join(self.state_dir, "sparkplug-bdseq"), encoding="utf-8") as f:
            return f.read().strip()

    def assert_ndeath(self, message, bdseq):
        """An NDEATH: only bdSeq (Int64), no seq, QoS 1, not retained."""
        self.assertEqual([(m["name"], m["datatype"], m["value"]) for m in message.metrics], [("bdSeq", "Int64", bdseq)])
        self.assertIsNone(message.seq, message)
        self.assertEqual((message.qos, message.retained), (1, False), message)

    def bdseq_of(self, nbirth):
        metric = nbirth.metric("bdSeq")
        self.assertIsNotNone(metric, nbirth)
        return metric["value"]

    def broker_line(self, broker, text, start, timeout=TIMEOUT):
        found = broker.wait_line(lambda line: text in line, timeout, start)
        self.assertIsNotNone(found, "mosquitto did not log %r:\n%s" % (text, broker.text()))
        return found

    def quiet(self, seconds):
        """A bounded pause for a negative check (nothing may happen meanwhile)."""
        simlib.wait_until(lambda: False, seconds, interval=0.05)


class Births(SparkplugCell):

    def test_births_seq_and_data_on_change(self):
        self.start(r6=True)
        nbirth, births = self.wait_births(devices=DEVICES + ("r6",))

        # NBIRTH: seq 0, QoS 0, bdSeq 0 on a first start (and on disk), Rebirth false.
        self.assertEqual((nbirth.seq, nbirth.qos, nbirth.retained), (0, 0, False), nbirth)
        self.assertIsNotNone(nbirth.payload["timestamp"])
        self.assertEqual([(m["name"], m["datatype"], m["value"], m["alias"]) for m in nbirth.metrics[:2]],
                         [("bdSeq", "Int64", 0, None), ("Node Control/Rebirth", "Boolean", False, None)])
        self.assertEqual(self.bdseq_file(), "0")
        expected = {"Properties/Software Version": "String", "Properties/JSON Bridge": "String",
                    "Properties/Commands Accepted": "UInt64", "Properties/Commands Refused": "UInt64",
                    "Upstreams/r6/Link": "String"}
        for line in LINES:
            expected.update({"Lines/%s/Up" % line: "Boolean", "Lines/%s/Requests" % line: "UInt64",
                             "Lines/%s/Timeouts" % line: "UInt64", "Lines/%s/Transactions Per Second" % line: "Double",
                             "Lines/%s/Utilisation Pct" % line: "Double"})
        got = {m["name"]: m["datatype"] for m in nbirth.metrics}
        self.assertEqual({name: got.get(name) for name in expected}, expected)
        for metric in nbirth.metrics:
            self.assertIsNotNone(metric["timestamp"], metric)
        version = subprocess.run(target_command(gatewaylib.GATEWAY, "--version"), capture_output=True, text=True,
                                 timeout=30, env=gatewaylib.environment()).stdout.split()[-1]
        self.assertIn(version, nbirth.metric("Properties/Software Version")["value"])
        self.assertIn(nbirth.metric("Properties/JSON Bridge")["value"], ("connected", "connecting"))
        self.assertEqual((nbirth.metric("Properties/Commands Accepted")["value"],
                          nbirth.metric("Properties/Commands Refused")["value"]), (0, 0))
        self.assertTrue(nbirth.metric("Upstreams/r6/Link")["value"])
        # Its own connection: MQTT 3.1.1 (p2), clean session (c1), keep alive 5 s.
        self.broker_line(self.broker, "as %s (p2, c1, k5)" % CLIENT_ID, 0)

        # DBIRTHs: after the NBIRTH, QoS 0, each metric with name, alias, datatype and a
        # timestamp; aliases unique across the node.
        aliases = [m["alias"] for m in nbirth.metrics if m["alias"] is not None]
        for device, dbirth in births.items():
            self.assertGreater(dbirth.index, nbirth.index)
            self.assertEqual((dbirth.qos, dbirth.retained), (0, False), dbirth)
            for metric in dbirth.metrics:
                self.assertTrue(metric["name"] and metric["datatype"], (device, metric))
                self.assertIsNotNone(metric["alias"], (device, metric))
                self.assertIsNotNone(metric["timestamp"], (device, metric))
                aliases.append(metric["alias"])
        self.assertEqual(len(aliases), len(set(aliases)), "aliases not unique across the node: %s" % sorted(aliases))

        # The WTEC RTU: every JSON state field is a metric of the same name, value and
        # type; engUnit where the JSON has a unit; writable on force, speed and target only.
        # Values: the host's view (the birth, or a DDATA for a field the birth had as null).
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        wtec = self.wait_dbirth_with("gripper-3", WTEC_RTU_FIELDS)
        self.assertEqual(field_names(wtec), WTEC_RTU_FIELDS)
        state, values = self.wait_view_matches_json("gripper-3")
        self.assertEqual(set(state["fields"]), WTEC_RTU_FIELDS)
        metrics = wtec.by_name()
        for field, value in state["fields"].items():
            metric = metrics[field]
            self.assertEqual((metric["datatype"], values[field]), (JSON_TYPES[type(value)], value), field)
            self.assertIn(metric["value"], (None, value), field)
            props = dict(metric["properties"])
            unit = state.get("units", {}).get(field)
            self.assertEqual(props.pop("engUnit", None), STRING_UNIT(unit) if unit else None, field)
            self.assertEqual(props.pop("writable", None), WRITABLE if field in WTEC_WRITABLE else None, field)
            self.assertEqual(props, {}, field)
        self.assertEqual(metrics["force_pct"]["properties"]["engUnit"], STRING_UNIT("%"))
        # Ops with parameters: Commands/<op> (Boolean false) and its fields, writable.
        for name, datatype in (("Commands/position", "Boolean"), ("Commands/position/percent", "Int64"),
                               ("Commands/force/percent", "Int64"), ("Commands/grip/force_pct", "Int64")):
            self.assertIn(name, metrics)
            self.assertEqual((metrics[name]["datatype"], metrics[name]["properties"].get("writable")),
                             (datatype, WRITABLE), name)
        self.assertIs(metrics["Commands/position"]["value"], False)

        # The XEG: position_mm (Double, mm, read-only); Commands/move with its two numbers
        # (Double), trigger's index (Int64). The EXCD: a choice (String), a Boolean.
        xeg = self.wait_json("gripper-1", lambda s: "model" in s["fields"] and "position_mm" in s["fields"])
        gripper = self.wait_dbirth_with("gripper-1", set(xeg["fields"])).by_name()
        self.assertEqual((gripper["position_mm"]["datatype"], gripper["position_mm"]["properties"]),
                         ("Double", {"engUnit": STRING_UNIT("mm")}))
        self.assertEqual((gripper["status"]["datatype"], gripper["status_code"]["datatype"]), ("String", "Int64"))
        xeg, xeg_values = self.wait_view_matches_json("gripper-1")
        self.assertEqual(xeg_values["model"], xeg["fields"]["model"])
        for name, datatype in (("Commands/move", "Boolean"), ("Commands/move/position_mm", "Double"),
                               ("Commands/move/speed_mm_s", "Double"), ("Commands/trigger/index", "Int64")):
            self.assertIn(name, gripper)
            self.assertEqual((gripper[name]["datatype"], gripper[name]["properties"].get("writable")),
                             (datatype, WRITABLE), name)
        stepper = births["stepper-1"].by_name()
        for name, datatype in (("Commands/jog/direction", "String"), ("Commands/stop/immediate", "Boolean"),
                               ("Commands/abs/position", "Int64")):
            self.assertIn(name, stepper)
            self.assertEqual((stepper[name]["datatype"], stepper[name]["properties"].get("writable")),
                             (datatype, WRITABLE), name)

        # DDATA on change only: the XEG homes (0 -> 32 mm in 3.2 s); its position_mm
        # alias comes in DDATA, by alias only, up to 32.0; the still devices publish nothing.
        # The still devices first read all their points: a point whose block has not been
        # read yet is null in the birth, and its first value is a change (CI under
        # qemu-user saw the EXCD's encoder and alarm code arrive after the mark).
        for device in ("stepper-1", "gripper-3"):
            points = {name for name in births[device].by_name() if "/" not in name}
            self.wait_json(device, lambda s, points=points: points <= set(s["fields"]))
            self.wait_view_matches_json(device)
        position_alias = gripper["position_mm"]["alias"]
        client = self.client()
        mark = self.spb.mark()
        self.assert_ok(client.write_registers(0x0610, [1], slave=1))
        self.wait_value(lambda: self.read_input(client, 0x0300, 2, 1), [3200, 0], MOTION_TIMEOUT, "XEG homed")
        self.ddata_with("gripper-1", position_alias, 32.0, mark)
        self.quiet(1.5)
        since = self.spb.messages(mark)
        positions = []
        known = NodeView.of(self.spb.messages()).device_alias
        for message in since:
            if message.kind != "DDATA":
                continue
            for metric in message.metrics:
                self.assertEqual((metric["name"], metric["datatype"]), (None, None), message)
                self.assertIsNotNone(metric["timestamp"], message)
                self.assertIn(metric["alias"], known[message.device], message)
                if message.device == "gripper-1" and metric["alias"] == position_alias:
                    positions.append(metric["value"])
        self.assertGreaterEqual(len(positions), 2, positions)
        self.assertEqual(positions, sorted(positions), "the jaws only opened: %s" % positions)
        self.assertEqual(positions[-1], 32.0)
        # (The replay of what the cell made before the first connection may still be going
        # out: historical, not a change.)
        for device in ("stepper-1", "gripper-3"):
            self.assertEqual([m for m in since if m.device == device and m.kind in NODE_MESSAGES and not m.historical],
                             [], "%s did not change but published" % device)

        # NDATA: node metrics change (requests counted), at most every 5 s; a metric by
        # alias only when its birth gave it one, else by name; no datatype (the birth's).
        self.wait_node_metric("Lines/line-a/Up", lambda up: up is True, nbirth.index, TIMEOUT)
        requests = nbirth.metric("Lines/line-a/Requests")["value"]
        self.wait_node_metric("Lines/line-a/Requests", lambda n: n > requests, nbirth.index, 2 * NDATA_PERIOD + 5)
        self.assertIsNotNone(self.spb.wait(
            lambda m: m.kind == "NDATA" and len(self.spb.messages(nbirth.index, kind="NDATA")) >= 2,
            2 * NDATA_PERIOD + 5, nbirth.index), "fewer than two NDATA in %.0f s" % (2 * NDATA_PERIOD + 5))
        ndata = self.spb.messages(nbirth.index, kind="NDATA")
        node_aliases = {m["alias"] for m in nbirth.metrics if m["alias"] is not None}
        unaliased = {m["name"] for m in nbirth.metrics if m["alias"] is None}
        for message in ndata:
            for metric in message.metrics:
                self.assertIsNone(metric["datatype"], message)
                if metric["name"] is None:
                    self.assertIn(metric["alias"], node_aliases, message)
                else:
                    self.assertEqual(metric["alias"], None, message)
                    self.assertIn(metric["name"], unaliased, message)
        stamps = [m.payload["timestamp"] for m in ndata]
        for before, after in zip(stamps, stamps[1:]):
            # (a sampling tick may run late under load, the next one on time)
            self.assertGreaterEqual(after - before, NDATA_PERIOD * 1000 - 1000, "NDATA sooner than 5 s: %s" % stamps)

        # seq +1 on every message of the session.
        self.assert_seq()
        self.assertEqual(len(self.spb.messages(kind="NBIRTH")), 1)
        self.assertEqual(NodeView.of(self.spb.messages()).unknown_aliases, [])


class Rebirth(SparkplugCell):

    def test_ncmd_rebirth(self):
        self.start()
        nbirth, births = self.wait_births()
        bdseq = self.bdseq_of(nbirth)
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        before = self.wait_dbirth_with("gripper-3", WTEC_RTU_FIELDS)
        state, _ = self.wait_view_matches_json("gripper-3")
        mark = self.spb.mark()
        self.ncmd([{"name": "Node Control/Rebirth", "datatype": "Boolean", "value": True}])
        again = self.spb.wait_kind("NBIRTH", TIMEOUT, mark)
        self.assertIsNotNone(again, "no NBIRTH after the rebirth request:\n" + self.spb.dump(mark))
        self.assertEqual((again.seq, self.bdseq_of(again)), (0, bdseq))
        self.assertIs(again.metric("Node Control/Rebirth")["value"], False)
        _, rebirths = self.wait_births(start=mark)
        # Every DBIRTH right after the NBIRTH (seq 1..4), no data in between.
        session = [m for m in self.spb.messages(again.index) if m.kind in NODE_MESSAGES]
        self.assertEqual(sorted(m.device for m in session[1:5]), sorted(DEVICES), session[:6])
        self.assertEqual([m.kind for m in session[1:5]], ["DBIRTH"] * 4, session[:6])
        self.assertEqual(sorted(m.seq for m in session[1:5]), [1, 2, 3, 4])
        # The same aliases; the current values (every field read by now: none null).
        after = rebirths["gripper-3"].by_name()
        for name, metric in before.by_name().items():
            self.assertEqual(after[name]["alias"], metric["alias"], name)
        self.assertEqual({field: after[field]["value"] for field in WTEC_RTU_FIELDS}, state["fields"])
        self.assertEqual(self.bdseq_file(), str(bdseq))
        self.assertEqual(self.spb.messages(kind="NDEATH"), [])
        self.assert_seq()


class CommandsAccepted(SparkplugCell):

    def test_dcmd_writes(self):
        self.start()
        self.wait_births()
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        wtec = self.wait_dbirth_with("gripper-3", WTEC_RTU_FIELDS).by_name()
        client = self.client()
        force, speed = self.read_holding(client, 0x0103, 2, 4)
        self.assertNotIn(force, (40,))
        self.assertNotIn(speed, (55,))

        # WTEC RTU: force_pct by name (Int64) -> the register, the JSON state, DDATA.
        mark, json_mark = self.spb.mark(), self.json.mark()
        self.dcmd("gripper-3", [{"name": "force_pct", "datatype": "Int64", "value": 40}])
        self.wait_value(lambda: self.read_holding(client, 0x0103, 1, 4), [40], TIMEOUT, "the WTEC force register")
        self.wait_json("gripper-3", lambda s: s["fields"]["force_pct"] == 40, json_mark)
        self.ddata_with("gripper-3", wtec["force_pct"]["alias"], 40, mark)
        # speed_pct by alias, without a datatype.
        mark = self.spb.mark()
        self.dcmd("gripper-3", [{"alias": wtec["speed_pct"]["alias"], "value": 55}])
        self.wait_value(lambda: self.read_holding(client, 0x0104, 1, 4), [55], TIMEOUT, "the WTEC speed register")
        self.ddata_with("gripper-3", wtec["speed_pct"]["alias"], 55, mark)

        # XEG: homed through Modbus TCP (a move needs it), then Commands/move with its
        # parameters in the same DCMD.
        xeg = self.wait_dbirth_with("gripper-1", {"position_mm", "Commands/move", "Commands/move/position_mm"})
        xeg = xeg.by_name()
        self.assert_ok(client.write_registers(0x0610, [1], slave=1))
        self.wait_value(lambda: self.read_input(client, 0x0300, 2, 1), [3200, 0], MOTION_TIMEOUT, "XEG homed")
        mark, json_mark = self.spb.mark(), self.json.mark()
        self.dcmd("gripper-1", [{"name": "Commands/move/position_mm", "datatype": "Double", "value": 10.0},
                                {"name": "Commands/move/speed_mm_s", "datatype": "Double", "value": 20.0},
                                {"name": "Commands/move", "datatype": "Boolean", "value": True}])
        self.wait_value(lambda: self.read_input(client, 0x0300, 2, 1), [1000, 2], MOTION_TIMEOUT,
                        "XEG positioned at 10 mm")
        self.wait_json("gripper-1", lambda s: s["fields"]["position_mm"] == 10.0
                       and s["fields"]["status"] == "positioned", json_mark)
        self.ddata_with("gripper-1", xeg["position_mm"]["alias"], 10.0, mark)

        # A parameter alone is stored and echoed in DDATA; nothing moves.
        mark = self.spb.mark()
        self.dcmd("gripper-1", [{"name": "Commands/move/position_mm", "datatype": "Double", "value": 12.0}])
        self.ddata_with("gripper-1", xeg["Commands/move/position_mm"]["alias"], 12.0, mark)
        self.quiet(0.5)
        self.assertEqual(self.read_input(client, 0x0300, 2, 1), [1000, 2], "a parameter alone moved the XEG")
        # Commands/move alone: the stored position (12) and speed (20).
        self.dcmd("gripper-1", [{"alias": xeg["Commands/move"]["alias"], "datatype": "Boolean", "value": True}])
        self.wait_value(lambda: self.read_input(client, 0x0300, 2, 1), [1200, 2], MOTION_TIMEOUT,
                        "XEG positioned at 12 mm with the stored parameters")
        self.assertEqual(self.read_holding(client, 0x0103, 2, 4), [40, 55])

        # Counted as accepted, none refused.
        self.wait_node_metric("Properties/Commands Accepted", lambda n: n >= 4, 0, 2 * NDATA_PERIOD + 5)
        self.assertEqual(NodeView.of(self.spb.messages()).node["Properties/Commands Refused"], 0)
        self.assert_seq()


class CommandsRefused(SparkplugCell):

    def test_refused_dcmd_writes_nothing_and_is_counted(self):
        self.start()
        self.wait_births()
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        wtec = self.wait_dbirth_with("gripper-3", WTEC_RTU_FIELDS).by_name()
        self.wait_view_matches_json("gripper-3")
        client = self.client()
        # e-stop, force, speed, target
        before = self.read_holding(client, 0x0102, 4, 4)
        self.assertNotEqual(before[2], 66)
        cases = [
            [{"name": "colour", "datatype": "Int64", "value": 30}],                      # unknown name
            [{"alias": 999999, "datatype": "Int64", "value": 30}],                       # unknown alias
            [{"name": "position_pct", "datatype": "Int64", "value": 30}],                # read-only
            [{"alias": wtec["estop"]["alias"], "datatype": "Boolean", "value": True}],    # read-only, by alias
            [{"name": "force_pct", "datatype": "Double", "value": 45.0}],                # wrong datatype
            [{"name": "speed_pct", "datatype": "String", "value": "fast"}],              # wrong datatype
            [{"name": "force_pct", "datatype": "Int64", "value": 10}],                   # out of range (20-100)
            [{"name": "target_pct", "datatype": "Int64", "value": 150}],                 # out of range (0-100)
            # all or nothing: a good speed and a bad force
            [{"name": "speed_pct", "datatype": "Int64", "value": 66},
             {"name": "force_pct", "datatype": "Int64", "value": 5}],
            # an op with a parameter of the wrong type
            [{"name": "Commands/position/percent", "datatype": "String", "value": "half"},
             {"name": "Commands/position", "datatype": "Boolean", "value": True}],
        ]
        mark = self.spb.mark()
        for metrics in cases:
            self.dcmd("gripper-3", metrics)
        self.publish_bytes(spb_topic("DCMD", "gripper-3"), b"\x0a\xff\xff\x01")  # undecodable
        refused = len(cases) + 1
        self.wait_node_metric("Properties/Commands Refused", lambda n: n == refused, 0, 2 * NDATA_PERIOD + 5)
        self.assertEqual(self.read_holding(client, 0x0102, 4, 4), before, "a refused DCMD wrote something")
        # Nothing echoed for the written metrics of the refused commands. The data the
        # cell made before the node's first connection is replayed after the births as
        # historical, and may still be going out here: it is not an echo.
        touched = {wtec[name]["alias"] for name in ("force_pct", "speed_pct", "target_pct", "Commands/position",
                                                   "Commands/position/percent")}
        echoed = [m for m in self.spb.messages(mark, kind="DDATA", device="gripper-3")
                  if not m.historical and touched & {x["alias"] for x in m.metrics}]
        self.assertEqual(echoed, [])
        self.assertEqual(NodeView.of(self.spb.messages()).node["Properties/Commands Accepted"], 0)
        # The same path still works: a good force is written. 40 % reads back as 40 %:
        # the gripper keeps the force as a current of 0..0x3F, so 50 % would read 51 %
        # once the next poll replaces the value the write left in the cache.
        self.dcmd("gripper-3", [{"name": "force_pct", "datatype": "Int64", "value": 40}])
        self.wait_value(lambda: self.read_holding(client, 0x0103, 1, 4), [40], TIMEOUT, "the WTEC force register")
        self.assertEqual(self.gateway.running(), True)
        self.assert_seq()


class Deaths(SparkplugCell):

    def test_clean_stop_kill_and_bdseq_across_restarts(self):
        self.start(seed_bdseq=41)
        nbirth, _ = self.wait_births(devices=("gripper-3",))
        self.assertEqual((nbirth.seq, self.bdseq_of(nbirth)), (0, 42))
        self.assertEqual(self.bdseq_file(), "42")

        # SIGTERM: the node publishes NDEATH (the NBIRTH's bdSeq) and disconnects cleanly,
        # so the broker drops the will: exactly one NDEATH.
        mark, broker_mark = self.spb.mark(), self.broker.mark()
        self.gateway.signal(signal.SIGTERM)
        self.assertEqual(self.gateway.wait_exit(), 0)
        ndeath = self.spb.wait_kind("NDEATH", TIMEOUT, mark)
        self.assertIsNotNone(ndeath, "no NDEATH on a clean stop:\n" + self.spb.dump(mark))
        self.assert_ndeath(ndeath, 42)
        self.broker_line(self.broker, "Client %s disconnected." % CLIENT_ID, broker_mark)
        self.quiet(1.0)
        self.assertEqual(len(self.spb.messages(mark, kind="NDEATH")), 1, self.spb.dump(mark))

        # Restart: the next bdSeq from the file in state_dir.
        mark = self.spb.mark()
        self.start_gateway()
        nbirth, _ = self.wait_births(start=mark, devices=("gripper-3",))
        self.assertEqual((nbirth.seq, self.bdseq_of(nbirth)), (0, 43))
        self.assertEqual(self.bdseq_file(), "43")

        # SIGKILL: the broker publishes the will, NDEATH with the same bdSeq.
        mark = self.spb.mark()
        self.gateway.signal(signal.SIGKILL)
        self.gateway.wait_exit()
        will = self.spb.wait_kind("NDEATH", TIMEOUT, mark)
        self.assertIsNotNone(will, "no will (NDEATH) after SIGKILL:\n" + self.spb.dump(mark))
        self.assert_ndeath(will, 43)
        self.assert_seq()

    def test_bdseq_wraps_from_255_to_0(self):
        self.start(seed_bdseq=255)
        nbirth, _ = self.wait_births(devices=())
        self.assertEqual((nbirth.seq, self.bdseq_of(nbirth)), (0, 0))
        self.assertEqual(self.bdseq_file(), "0")


class DeviceOffline(SparkplugCell):

    def test_dead_device_gets_ddeath_then_dbirth(self):
        self.start()
        self.wait_births()
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        first = self.wait_dbirth_with("gripper-3", WTEC_RTU_FIELDS)
        mark, json_mark = self.spb.mark(), self.json.mark()
        self.control("fault line-b@1:dead")
        ddeath = self.spb.wait_kind("DDEATH", TIMEOUT, mark, device="gripper-3")
        self.assertIsNotNone(ddeath, "no DDEATH of gripper-3:\n" + self.spb.dump(mark))
        self.assertIsNotNone(ddeath.seq)
        self.assertFalse(ddeath.retained)
        self.wait_json("gripper-3", lambda s: s["online"] is False, json_mark)
        self.assertEqual([(m.kind, m.device) for m in self.spb.messages(mark)
                          if m.kind in ("DDEATH", "DBIRTH", "NDEATH")], [("DDEATH", "gripper-3")])

        mark = self.spb.mark()
        self.control("fault line-b@1:revive")
        again = self.spb.wait_kind("DBIRTH", TIMEOUT, mark, device="gripper-3")
        self.assertIsNotNone(again, "no DBIRTH of gripper-3 once it answers again:\n" + self.spb.dump(mark))
        # The same aliases for the same metrics.
        aliases = {m["name"]: m["alias"] for m in again.metrics}
        for metric in first.metrics:
            if metric["name"] in aliases:
                self.assertEqual(aliases[metric["name"]], metric["alias"], metric["name"])
        self.assertEqual(len(self.spb.messages(kind="NBIRTH")), 1, "the whole node was born again")
        self.assert_seq()

    def test_unplugged_line_gets_ddeath_then_dbirth(self):
        self.start()
        self.wait_births()
        mark = self.spb.mark()
        self.control("fault line-b:unplug:3000")
        ddeath = self.spb.wait_kind("DDEATH", TIMEOUT, mark, device="gripper-3")
        self.assertIsNotNone(ddeath, "no DDEATH of gripper-3 with its line unplugged:\n" + self.spb.dump(mark))
        again = self.spb.wait_kind("DBIRTH", TIMEOUT, ddeath.index + 1, device="gripper-3")
        self.assertIsNotNone(again, "no DBIRTH of gripper-3 once its line is back:\n" + self.spb.dump(mark))
        # No other device died: line-a was not touched.
        self.assertEqual({m.device for m in self.spb.messages(mark, kind="DDEATH")}, {"gripper-3"})
        self.assert_seq()


class PrimaryHost(SparkplugCell):

    def test_births_wait_for_the_host_and_offline_walks_to_the_next_server(self):
        self.start(primary=True, second_broker=True)
        # Connected to the first server and subscribed to the host's STATE: no births
        # while the host has said nothing.
        self.broker_line(self.broker, " %s 1 %s" % (CLIENT_ID, STATE_TOPIC), 0)
        self.quiet(2.0)
        self.assertEqual([m for m in self.spb.messages() if m.kind in NODE_MESSAGES], [])
        t0 = sparkplug_host.now_ms()
        mark = self.spb.mark()
        self.host_state(True, t0)
        nbirth, _ = self.wait_births(start=mark)
        bdseq = self.bdseq_of(nbirth)
        self.assertEqual(nbirth.seq, 0)

        # The host goes offline: NDEATH from the node (its bdSeq), a clean disconnect,
        # then the second server.
        mark, broker_mark, b_mark = self.spb.mark(), self.broker.mark(), self.broker_b.mark()
        self.host_state(False, t0 + 1000)
        ndeath = self.spb.wait_kind("NDEATH", TIMEOUT, mark)
        self.assertIsNotNone(ndeath, "no NDEATH when the host went offline:\n" + self.spb.dump(mark))
        self.assert_ndeath(ndeath, bdseq)
        self.broker_line(self.broker, "Client %s disconnected." % CLIENT_ID, broker_mark)
        self.broker_line(self.broker_b, "as %s (p2, c1, k5)" % CLIENT_ID, b_mark)
        self.broker_line(self.broker_b, " %s 1 %s" % (CLIENT_ID, STATE_TOPIC), b_mark)
        # The second server has no STATE of the host yet: no births there.
        self.quiet(1.5)
        self.assertEqual([m for m in self.spb_b.messages() if m.kind in NODE_MESSAGES], [])
        b_sub_mark = self.spb_b.mark()
        self.host_state(True, sparkplug_host.now_ms(), port=self.port_b)
        nbirth_b, _ = self.wait_births(self.spb_b, b_sub_mark)
        self.assertEqual((nbirth_b.seq, self.bdseq_of(nbirth_b)), (0, (bdseq + 1) % 256))
        # One server at a time: nothing more on the first one after its NDEATH (data made
        # before the STATE offline arrived may precede it).
        self.quiet(0.5)
        self.assertEqual([m.kind for m in self.spb.messages(ndeath.index) if m.kind in NODE_MESSAGES], ["NDEATH"],
                         self.spb.dump(mark))
        self.assert_seq()
        self.assert_seq(self.spb_b)

    def test_a_malformed_state_is_ignored_logged_escaped_and_the_session_goes_on(self):
        self.start(primary=True, before_gateway=lambda: self.host_state(True, sparkplug_host.now_ms()))
        nbirth, _ = self.wait_births()
        mark, log_mark = self.spb.mark(), len(self.gateway.text().splitlines())
        forged = "2026-01-01 00:00:00.000 [critical] forged"
        bad = [b"not json\n" + forged.encode(),                   # a forged log line inside
               b'{"online": false}',                               # no timestamp
               b'{"online": "no", "timestamp": 1}',                # not a Boolean
               b"\xff\xfe\x00" + b"x" * 100000]                    # binary, 100 kB
        for payload in bad:
            self.publish_bytes(STATE_TOPIC, payload, retain=True)
        found = simlib.wait_until(
            lambda: sum("STATE of primary host" in line and "is ignored" in line
                        for line in self.gateway.text().splitlines()[log_mark:]) >= len(bad), TIMEOUT, interval=0.1)
        self.assertTrue(found, "not every malformed STATE was logged:\n" + self.gateway.text())
        logged = self.gateway.text().splitlines()[log_mark:]
        self.assertFalse([line for line in logged if line.startswith(forged)], "a forged log line got through")
        self.assertLess(max(len(line) for line in logged), 1000, "a STATE was logged whole")
        # The session goes on: no death, and the host's next STATE still counts.
        self.quiet(1.0)
        self.assertEqual([m for m in self.spb.messages(mark) if m.kind in ("NDEATH", "NBIRTH")], [])
        self.assertTrue(self.gateway.running())
        self.host_state(False, sparkplug_host.now_ms())
        ndeath = self.spb.wait_kind("NDEATH", TIMEOUT, mark)
        self.assertIsNotNone(ndeath, "no NDEATH for the well-formed STATE offline:\n" + self.spb.dump(mark))
        self.assert_ndeath(ndeath, self.bdseq_of(nbirth))


class OfflineBuffer(SparkplugCell):

    def test_data_made_while_the_host_is_offline_is_replayed_as_historical(self):
        self.start(primary=True, before_gateway=lambda: self.host_state(True, sparkplug_host.now_ms()))
        nbirth, births = self.wait_births()
        bdseq = self.bdseq_of(nbirth)
        position_alias = births["gripper-1"].metric("position_mm")["alias"]
        client = self.client()
        self.assertEqual(self.read_input(client, 0x0300, 1, 1), [0], "the XEG starts closed, not homed")

        # The host goes offline: NDEATH, and the node connects again (the only server)
        # and finds the retained STATE offline: NDEATH and walk again, each connection
        # with the next bdSeq, never a birth.
        mark, broker_mark = self.spb.mark(), self.broker.mark()
        self.host_state(False, sparkplug_host.now_ms())
        ndeath = self.spb.wait_kind("NDEATH", TIMEOUT, mark)
        self.assertIsNotNone(ndeath, "no NDEATH when the host went offline:\n" + self.spb.dump(mark))
        self.assert_ndeath(ndeath, bdseq)
        self.broker_line(self.broker, "as %s (p2, c1, k5)" % CLIENT_ID, broker_mark)
        self.broker_line(self.broker, " %s 1 %s" % (CLIENT_ID, STATE_TOPIC), broker_mark)

        # Meanwhile the XEG homes: 0 -> 32 mm.
        json_mark = self.json.mark()
        self.assert_ok(client.write_registers(0x0610, [1], slave=1))
        self.wait_value(lambda: self.read_input(client, 0x0300, 2, 1), [3200, 0], MOTION_TIMEOUT, "XEG homed")
        self.wait_json("gripper-1", lambda s: s["fields"]["position_mm"] == 32.0, json_mark)
        self.quiet(0.5)
        # Data made before the STATE offline arrived may precede the first NDEATH; from
        # it on, only deaths.
        deaths = [m for m in self.spb.messages(mark) if m.kind in NODE_MESSAGES and m.index >= ndeath.index]
        self.assertEqual({m.kind for m in deaths}, {"NDEATH"})
        for number, death in enumerate(deaths):
            self.assert_ndeath(death, (bdseq + number) % 256)

        # The host is back: births with the current values, then the buffered data,
        # oldest first, every metric historical.
        mark = self.spb.mark()
        self.host_state(True, sparkplug_host.now_ms())
        again, rebirths = self.wait_births(start=mark)
        last_death = [m for m in self.spb.messages(kind="NDEATH") if m.index < again.index][-1]
        self.assertEqual((again.seq, self.bdseq_of(again)), (0, (self.bdseq_of(last_death) + 1) % 256))
        self.assertEqual(self.bdseq_file(), str(self.bdseq_of(again)))
        self.assertEqual(rebirths["gripper-1"].metric("position_mm")["value"], 32.0)
        self.ddata_with("gripper-1", position_alias, 32.0, again.index)
        self.quiet(0.5)
        session = [m for m in self.spb.messages(again.index) if m.kind in NODE_MESSAGES]
        historical = [m for m in session if any(x["is_historical"] for x in m.metrics)]
        self.assertTrue(historical, "nothing historical after the births:\n" + self.spb.dump(mark))
        last_birth = max(m.index for m in session if m.kind in ("NBIRTH", "DBIRTH"))
        positions, stamps = [], []
        for message in historical:
            self.assertGreater(message.index, last_birth, "historical data before the births end")
            self.assertTrue(all(x["is_historical"] for x in message.metrics), message)
            for metric in message.metrics:
                self.assertIsNotNone(metric["timestamp"], message)
                self.assertLess(metric["timestamp"], again.payload["timestamp"], message)
                stamps.append(metric["timestamp"])
                if message.device == "gripper-1" and metric["alias"] == position_alias:
                    positions.append(metric["value"])
        self.assertEqual(stamps, sorted(stamps), "not oldest first")
        self.assertGreaterEqual(len(positions), 2, positions)
        self.assertEqual(positions, sorted(positions))
        self.assertEqual(positions[-1], 32.0)
        self.assertLess(positions[0], 32.0)
        self.assert_seq()


METER_DEFINITION = """\
name: spb-meter
description: a meter written by the Sparkplug reload test
period: 200ms
points:
  - {{name: voltage, table: input, address: 0x0000, type: float32, unit: {unit}}}
  - {{name: status, table: input, address: 0x0004}}
"""

METER_LINE = """\
  - name: line-c
    port: {port}
    baud: 115200
    response_timeout: 300ms
    devices:
      - {{name: meter-1, type: spb-meter, address: 9, unit_id: 21, command_ttl: 2s}}
"""

STEPPER_LINE = "      - {name: stepper-1, type: excd203mb, address: 3, unit_id: 2, command_ttl: 2s}\n"


class Reload(SparkplugCell):
    """SIGHUP re-births only what changed (docs/sparkplug-session.md, "Reload")."""

    def write_meter_definition(self, unit):
        with open(os.path.join(self.definitions, "spb-meter.yaml"), "w", encoding="utf-8") as f:
            f.write(METER_DEFINITION.format(unit=unit))

    def assert_only(self, mark, expected):
        """From @p mark on, the births and deaths are exactly @p expected ((kind, device)
        pairs, in order)."""
        self.quiet(1.0)
        seen = [(m.kind, m.device) for m in self.spb.messages(mark)
                if m.kind in ("NBIRTH", "NDEATH", "DBIRTH", "DDEATH")]
        self.assertEqual(seen, expected, self.spb.dump(mark))

    def test_a_device_removed_added_or_changed_is_born_again_alone_and_a_line_removed_rebirths_the_node(self):
        self.definitions = self.path("devices")
        os.mkdir(self.definitions)
        self.write_meter_definition("V")
        line_c = METER_LINE.format(port=self.path("line-c"))
        self.start(extra_config="definitions: [%s]\n" % self.definitions, extra_lines=line_c,
                   sim_extra=("--definitions", self.definitions, "--bus", self.path("line-c") + ":spb-meter@9"))
        nbirth, births = self.wait_births(devices=DEVICES + ("meter-1",))
        bdseq = self.bdseq_of(nbirth)
        self.assertEqual(births["meter-1"].metric("voltage")["properties"]["engUnit"], STRING_UNIT("V"))

        # A device removed: its DDEATH, nothing else.
        mark = self.spb.mark()
        self.rewrite_config(STEPPER_LINE, "")
        self.reload()
        self.assertIsNotNone(self.spb.wait_kind("DDEATH", TIMEOUT, mark, device="stepper-1"),
                             "no DDEATH of the removed stepper-1:\n" + self.spb.dump(mark))
        self.assert_only(mark, [("DDEATH", "stepper-1")])

        # A device added (the same drive under a new name): its DBIRTH, nothing else.
        mark = self.spb.mark()
        self.rewrite_config("      - {name: gripper-2,", STEPPER_LINE.replace("stepper-1", "stepper-2")
                            + "      - {name: gripper-2,")
        self.reload()
        added = self.spb.wait_kind("DBIRTH", TIMEOUT, mark, device="stepper-2")
        self.assertIsNotNone(added, "no DBIRTH of the added stepper-2:\n" + self.spb.dump(mark))
        self.assertEqual(field_names(added), field_names(births["stepper-1"]))
        self.assert_only(mark, [("DBIRTH", "stepper-2")])

        # A device whose metric definitions changed (the unit of a point): DDEATH, then
        # DBIRTH with the new definition and the same aliases.
        mark = self.spb.mark()
        self.write_meter_definition("kV")
        self.reload()
        again = self.spb.wait(lambda m: m.kind == "DBIRTH" and m.device == "meter-1", TIMEOUT, mark)
        self.assertIsNotNone(again, "no DBIRTH of meter-1 with its new unit:\n" + self.spb.dump(mark))
        self.assertEqual(again.metric("voltage")["properties"]["engUnit"], STRING_UNIT("kV"))
        self.assertEqual(again.metric("voltage")["alias"], births["meter-1"].metric("voltage")["alias"])
        self.assert_only(mark, [("DDEATH", "meter-1"), ("DBIRTH", "meter-1")])

        # A line removed changes the node's own metrics (Lines/line-c/...): meter-1's
        # DDEATH, then the whole node is born again, same bdSeq, no NDEATH, without it.
        mark = self.spb.mark()
        self.rewrite_config(line_c, "")
        self.reload()
        rebirth, rebirths = self.wait_births(start=mark, devices=("gripper-1", "stepper-2", "gripper-2", "gripper-3"))
        self.assertEqual((rebirth.seq, self.bdseq_of(rebirth)), (0, bdseq))
        self.assertFalse([m for m in rebirth.metrics if m["name"].startswith("Lines/line-c/")], rebirth)
        self.assertTrue([m for m in rebirth.metrics if m["name"].startswith("Lines/line-a/")], rebirth)
        reborn = sorted(rebirths, key=lambda device: rebirths[device].index)
        self.assert_only(mark, [("DDEATH", "meter-1"), ("NBIRTH", None)] + [("DBIRTH", d) for d in reborn])
        self.assertEqual([m.kind for m in self.spb.messages(mark, device="meter-1")], ["DDEATH"])
        self.assertEqual(self.spb.messages(kind="NDEATH"), [])
        self.assert_seq()


class CommandFlood(SparkplugCell):
    """A host that floods DCMDs (good, refused and undecodable) costs the gateway bounded
    memory, the Modbus TCP side keeps answering, and a command after the flood works."""

    def test_a_dcmd_flood_is_bounded_and_the_gateway_stays_responsive(self):
        self.start()
        self.wait_births()
        self.wait_json("gripper-3", lambda s: set(s["fields"]) == WTEC_RTU_FIELDS)
        client = self.client()
        rss_before = gatewaylib.rss_kib(self.gateway.pid)
        topic = spb_topic("DCMD", "gripper-3")
        messages = []
        for number in range(3000):
            messages.append((topic, command_payload([{"name": "force_pct", "datatype": "Int64",
                                                      "value": 20 + number % 80}])))
            messages.append((topic, b"\x0a\xff\xff\x01"))  # undecodable
            messages.append((spb_topic("DCMD", "no-such-device"), messages[-2][1]))
        failures = []

        def flood():
            try:
                sparkplug_host.flood(self.mqtt_port, "fb-spb-flood", messages)
            except (OSError, AssertionError) as e:
                failures.append(e)
        flooder = threading.Thread(target=flood, daemon=True)
        started = time.monotonic()
        flooder.start()
        reads, slowest = 0, 0.0
        while flooder.is_alive() or reads < 20:
            asked = time.monotonic()
            self.read_input(client, 0x0300, 2, 1)
            slowest = max(slowest, time.monotonic() - asked)
            reads += 1
            self.assertLess(time.monotonic() - started, 120, "the flood did not end in 120 s")
        flooder.join(5)
        self.assertEqual(failures, [])
        # Refused, dropped (over the 64 waiting) or executed: counted, never queued
        # without bound.
        refused = self.wait_node_metric("Properties/Commands Refused", lambda n: n >= 1000, 0, 2 * NDATA_PERIOD + 10)
        grown = gatewaylib.rss_kib(self.gateway.pid) - rss_before
        print("flood of %d DCMDs: %d Modbus TCP reads meanwhile, the slowest %.3f s; %d refused or dropped, "
              "%d executed, %d KiB more resident" % (len(messages), reads, slowest, refused,
                                                     NodeView.of(self.spb.messages()).node["Properties/Commands Accepted"],
                                                     grown))
        self.assertLess(grown, 64 * 1024, "the flood cost %d KiB" % grown)
        # A command sent once the flood is over is executed (again while the last of
        # the flood still runs: at most 16 DCMDs at once). 100 % is a value no command of
        # the flood wrote, and one the gripper reads back unchanged (it keeps the force as
        # a current of 0..0x3F: 42 % would read 41 % at the next poll).
        def force_is_100():
            self.dcmd("gripper-3", [{"name": "force_pct", "datatype": "Int64", "value": 100}])
            return simlib.wait_until(lambda: self.read_holding(client, 0x0103, 1, 4) == [100], 5.0, interval=0.1)
        self.assertTrue(simlib.wait_until(force_is_100, 4 * TIMEOUT, interval=0.1),
                        "force_pct = 100 never reached the WTEC after the flood")
        self.assertTrue(self.gateway.running())
        self.assert_seq()


if __name__ == "__main__":
    gatewaylib.main()
