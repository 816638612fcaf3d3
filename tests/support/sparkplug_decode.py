#!/usr/bin/env python3
"""A Sparkplug B payload decoder of the tests' own, independent of the gateway's encoder.

It compiles the schema (gateway/northbound/sparkplug/sparkplug_b.proto, written from
the specification) with Debian's `protoc --python_out` into a temporary folder and
decodes with Debian's python3-protobuf; the values are read by the specification's
datatype rules ("Payloads", "Datatype Details"), written out here again, not taken
from the gateway. A test host (part C) imports it:

    from sparkplug_decode import SparkplugDecoder
    decoder = SparkplugDecoder()                 # compiles the schema once
    payload = decoder.decode(raw_bytes)          # a dict, see decode()
    raw = decoder.encode({"metrics": [...]})     # a host's NCMD/DCMD

As a program: sparkplug_decode.py FILE... prints each payload as JSON; with --lines it
reads `TOPIC HEX` lines from standard input (mosquitto_sub -F '%t %x') and prints one JSON
object per message, so a user can watch an edge node:

    mosquitto_sub -t 'spBv1.0/#' -F '%t %x' | python3 tests/support/sparkplug_decode.py --lines

and with --encode JSON it writes a host's NCMD/DCMD payload (JSON as decode() prints it)
to standard output, for `mosquitto_pub -s`.
"""

import importlib.util
import json
import math
import pathlib
import subprocess
import sys
import tempfile

PROTO = pathlib.Path(__file__).resolve().parents[2] / "gateway/northbound/sparkplug/sparkplug_b.proto"

# The specification's DataType enumeration ("Payloads", "Data Types").
DATATYPES = {
    0: "Unknown", 1: "Int8", 2: "Int16", 3: "Int32", 4: "Int64", 5: "UInt8", 6: "UInt16",
    7: "UInt32", 8: "UInt64", 9: "Float", 10: "Double", 11: "Boolean", 12: "String",
    13: "DateTime", 14: "Text", 15: "UUID", 16: "DataSet", 17: "Bytes", 18: "File",
    19: "Template", 20: "PropertySet", 21: "PropertySetList",
}
DATATYPE_CODES = {name: code for code, name in DATATYPES.items()}
_SIGNED_32 = {"Int8": 8, "Int16": 16, "Int32": 32}
_INT_VALUE = {"Int8", "Int16", "Int32", "UInt8", "UInt16", "UInt32"}
_LONG_VALUE = {"Int64", "UInt64", "DateTime"}


class DecodeError(Exception):
    """The bytes are not a Sparkplug B payload, or a value does not fit its datatype."""


def compile_schema(proto=PROTO, out_dir=None):
    """The module protoc generates for @proto (in @out_dir, else a temporary folder)."""
    proto = pathlib.Path(proto)
    out = pathlib.Path(out_dir) if out_dir else pathlib.Path(tempfile.mkdtemp(prefix="spb-schema-"))
    subprocess.run(["protoc", f"--proto_path={proto.parent}", f"--python_out={out}", str(proto)],
                   check=True, capture_output=True, text=True)
    generated = out / (proto.stem + "_pb2.py")
    spec = importlib.util.spec_from_file_location(proto.stem + "_pb2", generated)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _signed(raw, bits):
    """An int_value of a signed type: the 32-bit two's complement (or the type's width)."""
    if raw >= 1 << 31:
        raw -= 1 << 32
    elif raw >= 1 << (bits - 1) and bits < 32 and raw < 1 << bits:
        raw -= 1 << bits
    if not -(1 << (bits - 1)) <= raw < 1 << (bits - 1):
        raise DecodeError(f"int_value {raw} out of range for a {bits}-bit signed integer")
    return raw


def _value(message, datatype):
    """The value of a Metric or PropertyValue, read by @datatype (a name, or None)."""
    if message.HasField("is_null") and message.is_null:
        return None
    field = message.WhichOneof("value")
    if field is None:
        return None
    raw = getattr(message, field)
    if datatype is None:
        return raw
    expected = ("int_value" if datatype in _INT_VALUE else "long_value" if datatype in _LONG_VALUE
                else {"Float": "float_value", "Double": "double_value", "Boolean": "boolean_value",
                      "String": "string_value", "Text": "string_value"}.get(datatype))
    if field != expected:
        raise DecodeError(f"{field} does not hold a {datatype}")
    if datatype in _SIGNED_32:
        return _signed(raw, _SIGNED_32[datatype])
    if datatype == "Int64":
        return raw - (1 << 64) if raw >= 1 << 63 else raw
    return raw


def _datatype(message, field):
    if not message.HasField(field):
        return None
    code = getattr(message, field)
    return DATATYPES.get(code, f"DataType {code}")


class SparkplugDecoder:
    """Decodes (and, for a test host, encodes) Sparkplug B payloads."""

    def __init__(self, proto=PROTO, out_dir=None):
        self.schema = compile_schema(proto, out_dir)

    def decode(self, data):
        """{"timestamp", "seq" (None when absent), "metrics": [{"name", "alias", "timestamp",
        "datatype" (a name), "is_historical", "is_transient", "is_null", "value",
        "properties": {key: {"type", "value"}}}]}; absent optional fields are None."""
        payload = self.schema.Payload()
        try:
            payload.ParseFromString(bytes(data))
        except Exception as error:  # the library's DecodeError and friends
            raise DecodeError(f"not a Sparkplug B payload: {error}") from error
        metrics = []
        for metric in payload.metrics:
            datatype = _datatype(metric, "datatype")
            properties = {}
            if metric.HasField("properties"):
                if len(metric.properties.keys) != len(metric.properties.values):
                    raise DecodeError("property keys and values differ in number")
                for key, value in zip(metric.properties.keys, metric.properties.values):
                    ptype = _datatype(value, "type")
                    properties[key] = {"type": ptype, "value": _value(value, ptype)}
            metrics.append({
                "name": metric.name if metric.HasField("name") else None,
                "alias": metric.alias if metric.HasField("alias") else None,
                "timestamp": metric.timestamp if metric.HasField("timestamp") else None,
                "datatype": datatype,
                "is_historical": metric.is_historical,
                "is_transient": metric.is_transient,
                "is_null": metric.HasField("is_null") and metric.is_null,
                "value": _value(metric, datatype),
                "properties": properties,
            })
        return {
            "timestamp": payload.timestamp if payload.HasField("timestamp") else None,
            "seq": payload.seq if payload.HasField("seq") else None,
            "metrics": metrics,
        }

    def encode(self, payload):
        """Bytes of a payload given as decode() returns it (name/alias/datatype/value of
        each metric; properties left out): what a test host publishes as NCMD/DCMD."""
        message = self.schema.Payload()
        if payload.get("timestamp") is not None:
            message.timestamp = payload["timestamp"]
        if payload.get("seq") is not None:
            message.seq = payload["seq"]
        for item in payload.get("metrics", []):
            metric = message.metrics.add()
            if item.get("name") is not None:
                metric.name = item["name"]
            if item.get("alias") is not None:
                metric.alias = item["alias"]
            datatype = item.get("datatype")
            if datatype is not None:
                metric.datatype = DATATYPE_CODES[datatype]
            value = item.get("value")
            if value is None:
                metric.is_null = True
            elif isinstance(value, bool):
                metric.boolean_value = value
            elif isinstance(value, str):
                metric.string_value = value
            elif isinstance(value, float):
                if datatype == "Float":
                    metric.float_value = value
                else:
                    metric.double_value = value
            elif datatype in _INT_VALUE:
                metric.int_value = value & 0xFFFFFFFF
            else:
                metric.long_value = value & 0xFFFFFFFFFFFFFFFF
        return message.SerializeToString()


def _printable(value):
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def _watch(decoder, lines, out):
    """Decodes `TOPIC HEX` lines; a line that is not one is reported, not fatal."""
    for line in lines:
        topic, _, payload = line.rstrip("\n").rpartition(" ")
        if not topic:
            topic, payload = payload, ""
        try:
            decoded = decoder.decode(bytes.fromhex(payload))
            for metric in decoded["metrics"]:
                metric["value"] = _printable(metric["value"])
            record = {"topic": topic, **decoded}
        except Exception as e:  # noqa: BLE001 - a watcher reports any bad message and goes on
            record = {"topic": topic, "error": str(e)}
        out.write(json.dumps(record) + "\n")
        out.flush()


def main(argv):
    if len(argv) < 2:
        print("usage: sparkplug_decode.py FILE... | --lines | --encode JSON", file=sys.stderr)
        return 2
    try:
        decoder = SparkplugDecoder()
    except FileNotFoundError:
        print("sparkplug_decode.py: protoc is not installed: install Debian's protobuf-compiler "
              "(deploy/install-deps.sh does)", file=sys.stderr)
        return 1
    except ModuleNotFoundError as e:
        print("sparkplug_decode.py: %s cannot import %s (google.protobuf): install Debian's python3-protobuf "
              "(deploy/install-deps.sh does) and run this with /usr/bin/python3" % (sys.executable, e.name),
              file=sys.stderr)
        return 1
    if argv[1] == "--lines":
        _watch(decoder, sys.stdin, sys.stdout)
        return 0
    if argv[1] == "--encode" and len(argv) == 3:
        # A host's command: the payload as JSON (as decode() prints it) to bytes on stdout.
        sys.stdout.buffer.write(decoder.encode(json.loads(argv[2])))
        return 0
    for name in argv[1:]:
        decoded = decoder.decode(pathlib.Path(name).read_bytes())
        for metric in decoded["metrics"]:
            metric["value"] = _printable(metric["value"])
        print(json.dumps({"file": name, **decoded}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
