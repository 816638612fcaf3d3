"""Modbus TCP through the real gateway (issue 4): every exception code of the contract
(docs/modbus-tcp.md), pipelining on one connection, hostile clients (malformed
header, a connection flood, a client that never reads) and the R6 pass-through."""

import socket
import struct
import threading

import gatewaylib
import simlib
from gatewaylib import mbap, read_frame

XEG, EXCD, WTEC_ASCII, WTEC_RTU, R6 = 1, 2, 3, 4, 50
TIMEOUT = 10.0


def read_pdu(address, count, function=3):
    return struct.pack(">BHH", function, address, count)


class ExceptionCodes(gatewaylib.CellTestCase):

    def test_exception_contract(self):
        self.start_cell(
            # unit 7: an XEG address nobody simulates; line-c: a port that does not exist.
            extra_devices_a="      - {name: ghost, type: hiwin-xeg, address: 7, unit_id: 7}\n",
            extra_lines=("  - name: line-c\n    port: %s\n    devices:\n"
                         "      - {name: unplugged, type: hiwin-xeg, address: 1, unit_id: 9}\n"
                         % self.path("absent-port")),
            rules=("  rules:\n    - {units: [4], functions: [6], registers: {from: 0x0300, to: 0x0300},"
                   " action: deny}\n"))
        client = self.client()
        # 0x01: FC01 is not an XEG function code; an access rule denies.
        self.assert_exception(client.read_coils(0, count=1, slave=XEG), 0x01)
        self.assert_exception(client.write_register(0x0300, 1, slave=WTEC_RTU), 0x01)
        self.assertEqual(self.read_holding(client, 0x0300, 1, WTEC_RTU), [1])  # reads still allowed
        # 0x02: outside the map (a hole; the XEG's input register 0x0302).
        self.assert_exception(client.read_holding_registers(0x0700, count=1, slave=XEG), 0x02)
        self.assert_exception(client.read_input_registers(0x0302, count=1, slave=XEG), 0x02)
        # 0x03: value out of range (reset takes 0-1); quantity 0 and 126 (raw frames).
        self.assert_exception(client.write_register(0x0610, 2, slave=XEG), 0x03)
        sock = self.raw()
        sock.sendall(mbap(1, XEG, read_pdu(0x0300, 0, 4)) + mbap(2, XEG, read_pdu(0x0300, 126, 4)))
        answers = {}
        for _ in range(2):
            transaction, unit, pdu = read_frame(sock)
            answers[transaction] = pdu
        self.assertEqual(answers, {1: b"\x84\x03", 2: b"\x84\x03"})
        # 0x0A: no route; a line whose port is missing.
        self.assert_exception(client.read_holding_registers(0x0600, count=1, slave=99), 0x0A)
        self.assert_exception(client.read_input_registers(0x0300, count=1, slave=9), 0x0A)
        # 0x0B: a configured address nobody answers.
        self.assert_exception(client.read_input_registers(0x0300, count=1, slave=7), 0x0B)
        # 0x0B: a device whose replies the simulator drops (after its image went stale).
        self.control("fault line-b@1:drop")

        def no_answer():
            reply = client.read_holding_registers(0x0204, count=1, slave=WTEC_RTU)
            return reply.isError() and reply.exception_code == 0x0B
        self.assertTrue(simlib.wait_until(no_answer, TIMEOUT, interval=0.1), "no 0x0B with drop fault")
        self.control("fault clear")
        self.assertTrue(simlib.wait_until(
            lambda: not client.read_holding_registers(0x0204, count=1, slave=WTEC_RTU).isError(), TIMEOUT,
            interval=0.2), "the WTEC RTU gripper never came back after the fault was cleared")
        # A device exception passed through: the XEG refuses a move before a reset (0x04).
        self.assert_exception(client.write_registers(0x0630, [1000, 5000, 1], slave=XEG), 0x04)

    def test_queue_full_is_busy(self):
        self.start_cell(
            sim_line_b="wtec-rtu@1,wtec-rtu@2",
            extra_devices_b="      - {name: narrow, type: wtec-rtu, address: 2, unit_id: 8, queue_limit: 1,"
                            " max_age: 0ms, poll: {fast: 2s, slow: 10s}}\n")
        # The device's own start-up and slow polls occupy its queue of one for a moment
        # (the queue holds every class): wait until one read gets through.
        client = self.client()
        self.assertTrue(simlib.wait_until(
            lambda: not client.read_holding_registers(0x0204, count=1, slave=8).isError(), TIMEOUT, interval=0.05))
        socks = [self.raw() for _ in range(4)]
        codes = {}
        # A burst of 64 against a queue of one: busy for most, answered for the one the
        # queue had room for. The device polls seldom (its 50 ms status poll held the
        # queue of one through whole bursts under qemu-user); still, up to three bursts.
        for burst in range(3):
            for s_index, sock in enumerate(socks):
                sock.sendall(b"".join(mbap(burst * 1000 + s_index * 100 + i, 8, read_pdu(0x0204, 1))
                                      for i in range(16)))
            for sock in socks:
                for _ in range(16):
                    frame = read_frame(sock)
                    self.assertIsNotNone(frame, "a pipelined request was not answered")
                    _, unit, pdu = frame
                    self.assertEqual(unit, 8)
                    key = "ok" if pdu[0] == 3 else "0x%02X" % pdu[1]
                    codes[key] = codes.get(key, 0) + 1
            if "ok" in codes and "0x06" in codes:
                break
        self.assertIn("0x06", codes, codes)
        self.assertIn("ok", codes, codes)
        self.assertEqual(set(codes), {"ok", "0x06"}, codes)


class Pipelining(gatewaylib.CellTestCase):

    def test_requests_for_several_units_on_one_connection(self):
        self.start_cell()
        sock = self.raw()
        requests = [
            (101, XEG, read_pdu(0x0600, 1), b"\x03\x02\x0a\x20"),        # model XEG-32
            (102, EXCD, read_pdu(0x0002, 2), None),                       # htr pair
            (103, WTEC_ASCII, read_pdu(0x0303, 1), b"\x03\x02\x00\x05"),  # device ID 5
            (104, WTEC_RTU, read_pdu(0x0303, 1), b"\x03\x02\x00\x01"),    # device ID 1
            (105, XEG, read_pdu(0x0303, 4, 4), b"\x04\x08\x00\x03\x00\x00\x00\x01\x03\x74"),
            (106, 99, read_pdu(0, 1), b"\x83\x0a"),
            (107, XEG, read_pdu(0x0700, 1), b"\x83\x02"),
        ]
        sock.sendall(b"".join(mbap(t, u, pdu) for t, u, pdu, _ in requests))
        answers = {}
        for _ in requests:
            frame = read_frame(sock)
            self.assertIsNotNone(frame)
            answers[frame[0]] = frame[1:]
        self.assertEqual(sorted(answers), [t for t, _, _, _ in requests])
        for transaction, unit, _, expected in requests:
            got_unit, pdu = answers[transaction]
            self.assertEqual(got_unit, unit, transaction)
            if expected is not None:
                self.assertEqual(pdu, expected, transaction)
            else:
                self.assertEqual(pdu[:2], b"\x03\x04", transaction)


class HostileClients(gatewaylib.CellTestCase):

    def test_malformed_header_closes_only_that_connection(self):
        self.start_cell()
        client = self.client()
        for bad in (struct.pack(">HHHB", 1, 1, 6, XEG) + read_pdu(0x0600, 1),   # protocol id 1
                    struct.pack(">HHHB", 1, 0, 1, XEG),                         # no function code
                    struct.pack(">HHHB", 1, 0, 600, XEG) + b"\x03"):            # oversize
            hostile = self.raw()
            hostile.sendall(bad)
            self.assertTrue(gatewaylib.closed_by_server(hostile))
            self.assertEqual(self.read_holding(client, 0x0600, 1, XEG), [0x0A20])

    def test_connection_flood_beyond_max_connections(self):
        self.start_cell(max_connections=8)
        client = self.client()
        flood = []
        for _ in range(500):
            flood.append(socket.create_connection(("127.0.0.1", self.tcp_port), timeout=TIMEOUT))
        self.clients.extend(flood)
        self.assertEqual(self.read_holding(client, 0x0600, 1, XEG), [0x0A20])
        # The server closes the refused ones right after the handshake; 7 stay open.
        open_ones = [s for s in flood if not gatewaylib.closed_by_server(s, timeout=0.01)]
        self.assertLessEqual(len(open_ones), 7)
        for sock in open_ones:
            sock.sendall(mbap(5, XEG, read_pdu(0x0600, 1)))
            self.assertEqual(read_frame(sock), (5, XEG, b"\x03\x02\x0a\x20"))
        for sock in flood:
            sock.close()
        # With the flood gone a new client gets in.
        def new_client_served():
            try:
                with socket.create_connection(("127.0.0.1", self.tcp_port), timeout=2.0) as sock:
                    sock.sendall(mbap(6, XEG, read_pdu(0x0600, 1)))
                    return read_frame(sock) == (6, XEG, b"\x03\x02\x0a\x20")
            except OSError:
                return False
        self.assertTrue(simlib.wait_until(new_client_served, TIMEOUT, interval=0.1))

    def test_stalled_client_does_not_delay_another(self):
        self.start_cell()
        client = self.client()
        self.assertEqual(self.read_holding(client, 0x0600, 1, XEG), [0x0A20])
        stalled = self.raw()
        stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        # Reads the fast poll keeps fresh, mostly served from the image: the stalled
        # connection's buffers fill. (Up to 16 of its requests may still wait for the
        # XEG when the image is older than max_age, which can fill the XEG's queue, so
        # the other client reads other devices.)
        request = mbap(1, XEG, read_pdu(0x0300, 2, 4))
        stop = threading.Event()

        def flood():
            stalled.settimeout(0.2)
            while not stop.is_set():
                try:
                    stalled.sendall(request * 64)
                except (socket.timeout, OSError):
                    pass
        writer = threading.Thread(target=flood, daemon=True)
        writer.start()
        try:
            for _ in range(20):
                self.assertEqual(self.read_holding(client, 0x0205, 1, EXCD), [1])  # rby: idle
                self.assertEqual(self.read_holding(client, 0x0303, 1, WTEC_RTU), [1])  # device ID
        finally:
            stop.set()
            writer.join(TIMEOUT)


class R6PassThrough(gatewaylib.CellTestCase):
    # seed 004 printed exchanges (tests/integration/sim/test_r6_tcp.py), PDU only.
    EXCHANGES = [
        ("03 00 82 00 01", "03 02 00 02"),
        ("03 00 83 00 04", "03 08 00 00 00 00 00 00 00 01"),
        ("10 08 83 00 02 04 00 00 00 01", "10 08 83 00 02"),
        ("03 08 83 00 06", "03 0c 00 00 00 01 00 00 00 0a 00 00 00 05"),
        ("03 08 89 00 01", "03 02 00 03"),
        ("06 4e e8 00 64", "06 4e e8 00 64"),
        ("10 08 b3 00 02 04 00 00 00 01", "10 08 b3 00 02"),
    ]

    def test_manual_exchanges_byte_for_byte(self):
        self.start_cell(r6=True)
        sock = self.raw()
        for i, (request, response) in enumerate(self.EXCHANGES):
            sock.sendall(mbap(300 + i, R6, bytes.fromhex(request)))
            self.assertEqual(read_frame(sock), (300 + i, R6, bytes.fromhex(response)), request)

    def test_concurrent_counter_reads_get_their_own_counter(self):
        self.start_cell(r6=True)
        expected = {0: [0, 0, 0, 100], 1: [0, 1, 0, 0x0A, 0, 5]}
        failures = []

        def reader(counter):
            client = gatewaylib.ModbusTcpClient("127.0.0.1", port=self.tcp_port, timeout=TIMEOUT, retries=0)
            try:
                if not client.connect():
                    failures.append("cannot connect")
                    return
                for _ in range(25):
                    if client.write_registers(0x0883, [0, counter], slave=R6).isError():
                        failures.append("select %d refused" % counter)
                        return
                    reply = client.read_holding_registers(0x0883, count=6, slave=R6)
                    if reply.isError():
                        failures.append("read of counter %d: %r" % (counter, reply))
                        return
                    if reply.registers[:2] != [0, counter] or (counter == 1 and reply.registers != expected[1]):
                        failures.append("counter %d read %r" % (counter, reply.registers))
            finally:
                client.close()
        threads = [threading.Thread(target=reader, args=(c,), daemon=True) for c in (0, 1)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(60.0)
        self.assertFalse(any(t.is_alive() for t in threads), "a counter reader hung")
        self.assertEqual(failures, [])


if __name__ == "__main__":
    gatewaylib.main()
