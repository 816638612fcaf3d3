"""Hostile and careless clients against the real gateway (issue 12): a slowloris that
trickles bytes, a write pipelined just before a malformed header, oversized and
ambiguous MQTT commands, malformed replies from the R6, and a client that keeps a
stateful-sequence hold on the R6. Each test reproduces one reported defect."""

import json
import socket
import struct
import time

import gatewaylib
import simlib
from gatewaylib import mbap, read_frame

XEG, EXCD, R6 = 1, 2, 50
TIMEOUT = 10.0


def read_pdu(address, count, function=3):
    return struct.pack(">BHH", function, address, count)


def pair(value):
    value &= 0xFFFFFFFF
    return [value >> 16, value & 0xFFFF]


class TcpHygiene(gatewaylib.CellTestCase):

    def test_slowloris_is_cut_and_capped_per_address(self):
        # `rules` is inserted under modbus_tcp: the two limits of this test.
        self.start_cell(max_connections=8,
                        rules="  frame_timeout: 1s\n  max_connections_per_client: 4\n")
        # Eight connections from 127.0.0.2, each starting a frame it never finishes.
        slow = []
        for _ in range(8):
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.settimeout(TIMEOUT)
            sock.bind(("127.0.0.2", 0))
            sock.connect(("127.0.0.1", self.tcp_port))
            self.clients.append(sock)
            slow.append(sock)
        for sock in slow:
            try:
                sock.sendall(b"\x00")
            except OSError:
                pass  # already refused
        # Only four were let in, so a SCADA client from another address still is.
        client = self.client()
        self.assertEqual(self.read_holding(client, 0x0600, 1, XEG), [0x0A20])
        refused = [s for s in slow if gatewaylib.closed_by_server(s, timeout=0.2)]
        self.assertEqual(len(refused), 4)
        # The others trickle a byte every 300 ms: each is closed once its frame is
        # 1 s old, although it never stops sending.
        trickling = [s for s in slow if s not in refused]
        deadline = time.monotonic() + TIMEOUT
        while trickling and time.monotonic() < deadline:
            for sock in list(trickling):
                try:
                    sock.sendall(b"\x01")
                except OSError:
                    trickling.remove(sock)
                    continue
                if gatewaylib.closed_by_server(sock, timeout=0.3 / max(len(trickling), 1)):
                    trickling.remove(sock)
        self.assertEqual(trickling, [], "trickling connections were never closed")
        self.assertTrue(self.gateway.wait_line(lambda line: "frame_timeout" in line, TIMEOUT))
        self.assertTrue(self.gateway.wait_line(lambda line: "max_connections_per_client" in line, TIMEOUT))

    def test_write_before_a_malformed_header_is_answered(self):
        self.start_cell()
        sock = self.raw()
        write = struct.pack(">BHHB", 0x10, 0x0014, 2, 4) + struct.pack(">HH", *pair(123456))
        bad = struct.pack(">HHHB", 8, 1, 6, EXCD) + read_pdu(0x0014, 2)  # protocol id 1
        sock.sendall(mbap(7, EXCD, write) + bad)
        self.assertEqual(read_frame(sock), (7, EXCD, b"\x10\x00\x14\x00\x02"))
        self.assertTrue(gatewaylib.closed_by_server(sock))
        client = self.client()
        self.assertEqual(self.read_holding(client, 0x0014, 2, EXCD), pair(123456))


if __name__ == "__main__":
    gatewaylib.main()
