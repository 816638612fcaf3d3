#!/usr/bin/env python3
"""The gateway's Sparkplug B encoder read by the tests' own decoder
(tests/support/sparkplug_decode.py: protoc + python3-protobuf on the schema): every
field of an NBIRTH, a DDATA with aliases only and an NDEATH.
usage: test_python_decoder.py DUMP_PROGRAM"""

import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "support"))
from sparkplug_decode import DecodeError, SparkplugDecoder  # noqa: E402

T0 = 1700000000000


def check(condition, what):
    if not condition:
        raise AssertionError(what)


def main():
    dump = sys.argv[1]
    with tempfile.TemporaryDirectory(prefix="spb-python-") as tmp:
        subprocess.run([dump, tmp], check=True, timeout=60)
        decoder = SparkplugDecoder(out_dir=tmp)
        birth = decoder.decode(pathlib.Path(tmp, "nbirth.bin").read_bytes())
        data = decoder.decode(pathlib.Path(tmp, "ddata.bin").read_bytes())
        death = decoder.decode(pathlib.Path(tmp, "ndeath.bin").read_bytes())

    check(birth["timestamp"] == T0 and birth["seq"] == 0, f"NBIRTH header: {birth}")
    expected = [
        ("bdSeq", "Int64", 7), ("i8", "Int8", -128), ("i16", "Int16", -300),
        ("i32", "Int32", -2**31), ("i64", "Int64", -2**63), ("u8", "UInt8", 255),
        ("u16", "UInt16", 65535), ("u32", "UInt32", 2**32 - 1), ("u64", "UInt64", 2**64 - 1),
        ("position_mm", "Float", 12.5), ("ratio", "Double", -0.125),
        ("Node Control/Rebirth", "Boolean", False), ("name", "String", "gripper \u00e9"),
        ("when", "DateTime", T0), ("note", "Text", "text"), ("unknown_yet", "Double", None),
    ]
    check(len(birth["metrics"]) == len(expected), f"NBIRTH has {len(birth['metrics'])} metrics")
    for alias, ((name, datatype, value), metric) in enumerate(zip(expected, birth["metrics"])):
        got = (metric["name"], metric["alias"], metric["datatype"], metric["value"], metric["timestamp"])
        check(got == (name, alias, datatype, value, T0), f"NBIRTH metric {alias}: {got}")
        check(not metric["is_historical"] and not metric["is_transient"], f"flags of {name}")
        check(metric["is_null"] == (value is None), f"is_null of {name}")
        props = {"engUnit": {"type": "String", "value": "mm"}, "writable": {"type": "Boolean", "value": True}}
        check(metric["properties"] == (props if name == "position_mm" else {}), f"properties of {name}")

    check(data["timestamp"] == T0 + 1000 and data["seq"] == 1, f"DDATA header: {data}")
    got = [(m["name"], m["alias"], m["datatype"], m["value"], m["timestamp"], m["is_historical"])
           for m in data["metrics"]]
    # Without the datatype (it is in the birth), values are the raw fields: the host
    # reads them by the birth's datatype.
    check(got == [(None, 9, None, 13.0, T0 + 1000, False), (None, 2, None, 2**64 - 1, T0 + 1000, True)],
          f"DDATA metrics: {got}")

    check(death["seq"] is None and death["timestamp"] is None, f"NDEATH header: {death}")
    check([(m["name"], m["alias"], m["datatype"], m["value"]) for m in death["metrics"]] ==
          [("bdSeq", None, "Int64", 7)], f"NDEATH metrics: {death['metrics']}")

    # The decoder refuses what is not a payload.
    try:
        decoder.decode(b"\x12\x05ab")
        raise AssertionError("a truncated payload decoded")
    except DecodeError:
        pass
    # A host's DCMD from encode() reads back.
    dcmd = decoder.decode(decoder.encode({"metrics": [{"alias": 2, "datatype": "Int16", "value": -5}]}))
    check(dcmd["metrics"][0]["value"] == -5, f"DCMD round trip: {dcmd}")
    # Run as the README runs it, by an interpreter without python3-protobuf (-S: no
    # site or dist packages, as a virtualenv's python3 first in PATH): it says what to
    # install and which interpreter to use, and exits 1.
    script = pathlib.Path(__file__).resolve().parents[2] / "support" / "sparkplug_decode.py"
    bare = subprocess.run([sys.executable, "-S", str(script), "--lines"], input="", capture_output=True,
                          text=True, timeout=60)
    check(bare.returncode == 1 and "python3-protobuf" in bare.stderr and "/usr/bin/python3" in bare.stderr
          and "Traceback" not in bare.stderr, f"without google.protobuf: {bare.returncode} {bare.stderr!r}")
    print("test_python_decoder: NBIRTH (16 metrics), DDATA, NDEATH decoded as encoded; without python3-protobuf, "
          "an error that says what to install")


if __name__ == "__main__":
    main()
