"""A Sparkplug B host application for the end-to-end tests (issue 28, part C): what a
SCADA host does with the edge node's messages, built on mosquitto_sub / mosquitto_pub
and the tests' own payload decoder (tests/support/sparkplug_decode.py, independent of
the gateway's encoder).

- SparkplugSubscriber: mosquitto_sub printing '%r %q %t %x' (retain flag, QoS, topic,
  payload in hex) per message; each line is parsed into a Message whose payload is
  decoded (spBv1.0/<group>/... topics) or kept as text (spBv1.0/STATE/<host>).
- NodeView: the host's picture of the node, rebuilt from births and updated by data
  messages through the aliases of the births (values typed by the birth's datatype).
- seq_problems(): the seq rules (NBIRTH 0, +1 per message but NDEATH, 255 -> 0).
- command_payload(): an NCMD / DCMD payload, encoded by the tests' encoder.

Every wait is bounded; processes are gatewaylib.Process objects the test case kills in
its tearDown."""

import json
import pathlib
import socket
import struct
import sys
import time

import gatewaylib

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "support"))
from sparkplug_decode import DecodeError, SparkplugDecoder  # noqa: E402

NAMESPACE = "spBv1.0"
NODE_TYPES = ("NBIRTH", "NDEATH", "NDATA", "NCMD")
DEVICE_TYPES = ("DBIRTH", "DDEATH", "DDATA", "DCMD")
# What the edge node publishes (the host's own NCMD / DCMD / STATE are not).
NODE_MESSAGES = ("NBIRTH", "NDEATH", "NDATA", "DBIRTH", "DDEATH", "DDATA")

_decoder = None


def decoder():
    """One SparkplugDecoder for the process (protoc runs once)."""
    global _decoder
    if _decoder is None:
        _decoder = SparkplugDecoder()
    return _decoder


def now_ms():
    return int(time.time() * 1000)


class Message:
    """One message as the host received it.

    kind: NBIRTH, DDATA, ..., STATE, or None for another topic; group, edge, device
    (None for node messages), host (STATE); payload: the decoded dict (decode() of
    sparkplug_decode.py), the STATE's JSON (a dict, or None when it is not JSON), or
    None when undecodable (error says why); raw: the bytes; index: the line's
    position in the subscriber's output."""

    def __init__(self, line, index):
        self.index = index
        retained, qos, topic, payload_hex = (line.split(" ", 3) + [""])[:4]
        self.retained = retained == "1"
        self.qos = int(qos)
        self.topic = topic
        self.raw = bytes.fromhex(payload_hex)
        self.kind = self.group = self.edge = self.device = self.host = None
        self.payload = None
        self.error = None
        levels = topic.split("/")
        if len(levels) == 3 and levels[0] == NAMESPACE and levels[1] == "STATE":
            self.kind, self.host = "STATE", levels[2]
            try:
                self.payload = json.loads(self.raw.decode("utf-8"))
            except ValueError as e:
                self.error = str(e)
            return
        if len(levels) in (4, 5) and levels[0] == NAMESPACE:
            self.group, self.kind, self.edge = levels[1], levels[2], levels[3]
            self.device = levels[4] if len(levels) == 5 else None
            try:
                self.payload = decoder().decode(self.raw)
            except DecodeError as e:
                self.error = str(e)

    @property
    def seq(self):
        return self.payload["seq"] if isinstance(self.payload, dict) else None

    @property
    def metrics(self):
        return self.payload["metrics"] if self.payload and "metrics" in self.payload else []

    @property
    def historical(self):
        """True for data replayed from the node's offline buffer: every metric is_historical
        (the data a cell made before the node's first connection is such a replay)."""
        return bool(self.metrics) and all(m.get("is_historical") for m in self.metrics)

    def metric(self, name):
        """The metric named @p name (births carry names), None when absent."""
        for metric in self.metrics:
            if metric["name"] == name:
                return metric
        return None

    def by_name(self):
        return {m["name"]: m for m in self.metrics}

    def __repr__(self):
        if self.kind in NODE_MESSAGES + ("NCMD", "DCMD") and self.payload is not None:
            shown = [(m["name"] if m["name"] is not None else m["alias"], m["value"]) for m in self.metrics]
            if len(shown) > 8:
                shown = shown[:8] + ["... %d metrics" % len(shown)]
            return "<%s %s seq=%s qos=%d retained=%d%s %s>" % (self.kind, self.device or "", self.seq, self.qos,
                                                               self.retained, " historical" if self.historical else "",
                                                               shown)
        return "<%s qos=%d retained=%d %r%s>" % (self.topic, self.qos, self.retained, self.raw[:120],
                                                 " error: " + self.error if self.error else "")


class SparkplugSubscriber(gatewaylib.Process):
    """mosquitto_sub with one line per message: retain flag, QoS, topic, hex payload."""

    FORMAT = "%r %q %t %x"

    def __init__(self, *args, **kwargs):
        self._parsed = {}
        super().__init__(*args, **kwargs)

    def report(self):
        """The messages decoded, one a line (the raw log is hex)."""
        return self.dump()

    def _message(self, index, line):
        found = self._parsed.get(index)
        if found is None:
            found = self._parsed[index] = Message(line, index)
        return found

    def messages(self, start=0, kind=None, device=None):
        """Every message from line @p start on (of @p kind / @p device when given)."""
        with self._condition:
            lines = list(self.lines[start:])
        found = []
        for offset, line in enumerate(lines):
            if line is None:
                break
            message = self._message(start + offset, line)
            if (kind is None or message.kind == kind) and (device is None or message.device == device):
                found.append(message)
        return found

    def wait(self, predicate, timeout, start=0):
        """The first Message from line @p start on that satisfies @p predicate, or None
        at the deadline (or when mosquitto_sub ended)."""
        deadline = time.monotonic() + timeout
        position = start
        while True:
            for message in self.messages(position):
                position = message.index + 1
                if predicate(message):
                    return message
            remaining = deadline - time.monotonic()
            with self._condition:
                ended = position < len(self.lines) and self.lines[position] is None
            if remaining <= 0 or ended:
                return None
            with self._condition:
                self._condition.wait_for(lambda: len(self.lines) > position, remaining)

    def wait_kind(self, kind, timeout, start=0, device=None, check=lambda m: True):
        return self.wait(lambda m: m.kind == kind and (device is None or m.device == device) and check(m),
                         timeout, start)

    def dump(self, start=0):
        return "\n".join(repr(m) for m in self.messages(start))


def typed(value, datatype):
    """A value as a host reads it by the birth's @p datatype: data messages leave the
    datatype out, so the decoder gives int_value / long_value unsigned."""
    if value is None or datatype is None or not isinstance(value, int) or isinstance(value, bool):
        return value
    bits = {"Int8": 8, "Int16": 16, "Int32": 32, "Int64": 64}.get(datatype)
    if bits is None:
        return value
    width = 64 if bits == 64 else 32
    value &= (1 << width) - 1
    if value >= 1 << (width - 1):
        value -= 1 << width
    return value


class NodeView:
    """The host's view of one edge node: node metrics and each device's metrics by
    name, with the alias maps and datatypes of the latest births."""

    def __init__(self):
        self.node = {}           # name -> value
        self.node_types = {}     # name -> datatype
        self.node_alias = {}     # alias -> name
        self.devices = {}        # device -> {name: value}
        self.device_types = {}   # device -> {name: datatype}
        self.device_alias = {}   # device -> {alias: name}
        self.online = set()
        self.unknown_aliases = []  # (message, alias) of data naming an alias no birth gave

    def apply(self, message):
        if message.payload is None or message.kind not in NODE_MESSAGES:
            return
        if message.kind == "NBIRTH":
            self.node, self.node_types, self.node_alias = {}, {}, {}
            self.online = set()
            for metric in message.metrics:
                self.node[metric["name"]] = metric["value"]
                self.node_types[metric["name"]] = metric["datatype"]
                if metric["alias"] is not None:
                    self.node_alias[metric["alias"]] = metric["name"]
        elif message.kind == "NDATA":
            self._update(message, self.node, self.node_types, self.node_alias)
        elif message.kind == "DBIRTH":
            values, types, aliases = {}, {}, {}
            for metric in message.metrics:
                values[metric["name"]] = metric["value"]
                types[metric["name"]] = metric["datatype"]
                if metric["alias"] is not None:
                    aliases[metric["alias"]] = metric["name"]
            self.devices[message.device] = values
            self.device_types[message.device] = types
            self.device_alias[message.device] = aliases
            self.online.add(message.device)
        elif message.kind == "DDATA":
            self._update(message, self.devices.setdefault(message.device, {}),
                         self.device_types.setdefault(message.device, {}),
                         self.device_alias.setdefault(message.device, {}))
        elif message.kind == "DDEATH":
            self.online.discard(message.device)

    def _update(self, message, values, types, aliases):
        for metric in message.metrics:
            name = metric["name"]
            if name is None:
                name = aliases.get(metric["alias"])
                if name is None:
                    self.unknown_aliases.append((message, metric["alias"]))
                    continue
            values[name] = typed(metric["value"], types.get(name))

    @classmethod
    def of(cls, messages):
        view = cls()
        for message in messages:
            view.apply(message)
        return view


def seq_problems(messages):
    """What breaks the seq rules in @p messages (the node's, in order): an NBIRTH with a
    seq other than 0, a message of the session whose seq is not the previous + 1 (255
    wrapping to 0), an NDEATH with a seq, a message without one. Empty when all hold."""
    problems = []
    previous = None
    for message in messages:
        if message.kind not in NODE_MESSAGES or message.payload is None:
            continue
        seq = message.seq
        if message.kind == "NDEATH":
            if seq is not None:
                problems.append("NDEATH with seq %s: %r" % (seq, message))
            previous = None
            continue
        if seq is None:
            problems.append("no seq: %r" % message)
            continue
        if message.kind == "NBIRTH":
            if seq != 0:
                problems.append("NBIRTH with seq %d: %r" % (seq, message))
            previous = seq
            continue
        if previous is not None and seq != (previous + 1) % 256:
            problems.append("seq %d after %d: %r" % (seq, previous, message))
        previous = seq
    return problems


def command_payload(metrics, seq=None):
    """An NCMD / DCMD payload: @p metrics is a list of dicts (name and/or alias,
    datatype, value), as sparkplug_decode's encode() takes them."""
    payload = {"timestamp": now_ms()}
    if seq is not None:
        payload["seq"] = seq
    payload["metrics"] = [dict(metric) for metric in metrics]
    return decoder().encode(payload)


def _mqtt_packet(kind, body):
    """An MQTT 3.1.1 control packet: fixed header (remaining length varint) and body."""
    length, encoded = len(body), bytearray()
    while True:
        byte, length = length % 128, length // 128
        encoded.append(byte | (0x80 if length else 0))
        if not length:
            return bytes([kind]) + bytes(encoded) + body


def _mqtt_string(data):
    return struct.pack(">H", len(data)) + data


def flood(port, client_id, messages, timeout=30.0):
    """Publishes @p messages ((topic, payload bytes) pairs) at QoS 0 as fast as one TCP
    connection to the broker on 127.0.0.1:@p port takes them (MQTT 3.1.1 written here:
    mosquitto_pub starts a process per message), then disconnects. A host that floods
    the node with commands."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as sock:
        connect = _mqtt_string(b"MQTT") + bytes([4, 0x02]) + struct.pack(">H", 30) + _mqtt_string(client_id.encode())
        sock.sendall(_mqtt_packet(0x10, connect))
        connack = sock.recv(4)
        if connack[:1] != b"\x20" or connack[3:4] != b"\x00":
            raise AssertionError("the broker refused the flooding client: %r" % connack)
        batch = bytearray()
        for topic, payload in messages:
            batch += _mqtt_packet(0x30, _mqtt_string(topic.encode()) + payload)
            if len(batch) >= 65536:
                sock.sendall(batch)
                batch.clear()
        sock.sendall(bytes(batch) + _mqtt_packet(0xE0, b""))


def state_payload(online, timestamp=None):
    """A Sparkplug 3.0 host STATE payload."""
    return json.dumps({"online": online, "timestamp": now_ms() if timestamp is None else timestamp})
