"""The gateway's Modbus TCP server (fb_modbus_tcp_test_server: register banks on
units 1 and 2, no serial lines) driven by real third-party clients: pymodbus
(Debian's python3-pymodbus), mbpoll, and raw sockets for pipelining and hostile
input. Run with the interpreter that has pymodbus (CMakeLists.txt picks /usr/bin/python3).

    test_modbus_tcp.py --server PATH/fb_modbus_tcp_test_server
"""

import argparse
import socket
import struct
import subprocess
import sys
import unittest

try:
    from pymodbus.client import ModbusTcpClient
    PYMODBUS_ERROR = None
except ImportError as e:  # reported as a failure by the tests that need it
    PYMODBUS_ERROR = e

SERVER = None
IO_TIMEOUT = 5.0


def mbap(transaction, unit, pdu, protocol=0, length=None):
    if length is None:
        length = len(pdu) + 1
    return struct.pack(">HHHB", transaction, protocol, length, unit) + pdu


def read_frame(sock):
    """One MBAP frame: (transaction, unit, pdu), or None when the server closed."""
    header = b""
    while len(header) < 6:
        chunk = sock.recv(6 - len(header))
        if not chunk:
            return None
        header += chunk
    transaction, protocol, length = struct.unpack(">HHH", header)
    body = b""
    while len(body) < length:
        chunk = sock.recv(length - len(body))
        if not chunk:
            return None
        body += chunk
    return transaction, body[0], body[1:]


def closed_by_server(sock):
    try:
        return sock.recv(1) == b""
    except ConnectionResetError:
        return True


class ServerProcess:
    def __init__(self, *args):
        self.process = subprocess.Popen([SERVER, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = self.process.stdout.readline()  # bounded: the server prints it or exits
        if not line.startswith("listening "):
            self.stop()
            raise RuntimeError(f"test server did not start: {line!r} {self.process.stderr.read()}")
        self.port = int(line.split()[1])

    def connect(self):
        sock = socket.create_connection(("127.0.0.1", self.port), timeout=IO_TIMEOUT)
        sock.settimeout(IO_TIMEOUT)
        return sock

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=IO_TIMEOUT)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=IO_TIMEOUT)
        self.stderr = self.process.stderr.read()
        self.process.stdout.close()
        self.process.stderr.close()


class ModbusTcpServerTest(unittest.TestCase):
    def setUp(self):
        self.server = ServerProcess("--idle-ms", "0")
        self.addCleanup(self.server.stop)

    def pymodbus_client(self):
        if PYMODBUS_ERROR is not None:
            self.fail(f"python3-pymodbus is needed: {PYMODBUS_ERROR}")
        client = ModbusTcpClient("127.0.0.1", port=self.server.port, timeout=IO_TIMEOUT)
        self.assertTrue(client.connect())
        self.addCleanup(client.close)
        return client

    def test_pymodbus_reads_writes_and_exceptions(self):
        client = self.pymodbus_client()
        reply = client.read_holding_registers(0x0300, count=2, slave=1)
        self.assertFalse(reply.isError(), reply)
        self.assertEqual(reply.registers, [0x0300, 0x0301])
        reply = client.write_register(10, 1234, slave=1)
        self.assertFalse(reply.isError(), reply)
        self.assertEqual(client.read_holding_registers(10, count=1, slave=1).registers, [1234])
        reply = client.write_registers(20, [7, 8, 9], slave=2)
        self.assertFalse(reply.isError(), reply)
        self.assertEqual(client.read_input_registers(20, count=3, slave=2).registers, [7, 8, 9])
        # Access rule: unit 2 registers 100-199 are not writable -> 0x01.
        reply = client.write_register(150, 1, slave=2)
        self.assertTrue(reply.isError())
        self.assertEqual(reply.exception_code, 0x01)
        self.assertEqual(client.read_holding_registers(150, count=1, slave=2).registers, [150])  # unchanged
        # No route -> 0x0A.
        reply = client.read_holding_registers(0, count=1, slave=9)
        self.assertTrue(reply.isError())
        self.assertEqual(reply.exception_code, 0x0A)

    def test_mbpoll_reads_and_writes(self):
        base = ["mbpoll", "-m", "tcp", "-p", str(self.server.port), "-a", "1", "-0", "-1", "-o", "2"]
        out = subprocess.run(base + ["-r", "768", "-c", "2", "127.0.0.1"], capture_output=True, text=True,
                             timeout=30)
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        self.assertIn("[768]: \t768", out.stdout)
        self.assertIn("[769]: \t769", out.stdout)
        out = subprocess.run(base + ["-r", "5", "127.0.0.1", "4321"], capture_output=True, text=True, timeout=30)
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        out = subprocess.run(base + ["-r", "5", "127.0.0.1"], capture_output=True, text=True, timeout=30)
        self.assertIn("[5]: \t4321", out.stdout)

    def test_pipelined_requests_each_get_their_transaction_id(self):
        sock = self.server.connect()
        self.addCleanup(sock.close)
        requests = b"".join(mbap(1000 + i, 1, struct.pack(">BHH", 3, i, 1)) for i in range(20))
        sock.sendall(requests)
        answers = {}
        for _ in range(20):
            frame = read_frame(sock)
            self.assertIsNotNone(frame)
            transaction, unit, pdu = frame
            answers[transaction] = (unit, pdu)
        self.assertEqual(sorted(answers), [1000 + i for i in range(20)])
        for i in range(20):
            self.assertEqual(answers[1000 + i], (1, struct.pack(">BBH", 3, 2, i)))

    def test_malformed_header_closes_only_that_connection(self):
        good = self.server.connect()
        self.addCleanup(good.close)
        for bad in (mbap(1, 1, b"\x03\x00\x00\x00\x01", protocol=1),   # protocol id 1
                    mbap(1, 1, b"", length=1),                          # no function code
                    struct.pack(">HHH", 1, 0, 600) + b"\x01\x03"):      # oversize
            hostile = self.server.connect()
            hostile.sendall(bad)
            self.assertTrue(closed_by_server(hostile))
            hostile.close()
            good.sendall(mbap(7, 1, struct.pack(">BHH", 3, 0, 1)))
            self.assertEqual(read_frame(good), (7, 1, b"\x03\x02\x00\x00"))


class ConnectionLimitTest(unittest.TestCase):
    def test_max_connections(self):
        server = ServerProcess("--max-connections", "4")
        self.addCleanup(server.stop)
        socks = [server.connect() for _ in range(10)]
        for sock in socks:
            self.addCleanup(sock.close)
        working = 0
        for i, sock in enumerate(socks):
            try:
                sock.sendall(mbap(i, 1, struct.pack(">BHH", 3, 0, 1)))
                if read_frame(sock) is not None:
                    working += 1
            except (ConnectionResetError, BrokenPipeError):
                pass
        self.assertEqual(working, 4)


def main():
    global SERVER
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True)
    args, rest = parser.parse_known_args()
    SERVER = args.server
    unittest.main(argv=[sys.argv[0], *rest])


if __name__ == "__main__":
    main()
