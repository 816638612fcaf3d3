"""Hostile and careless clients against the real gateway (issue 12): a slowloris that
trickles bytes, a write pipelined just before a malformed header, oversized and
ambiguous MQTT commands, malformed replies from the R6, and a client that keeps a
stateful-sequence hold on the R6. Each test reproduces one reported defect."""

import json
import os
import socket
import struct
import subprocess
import threading
import time

import gatewaylib
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


PREFIX = "fieldbridge/e2e"


class MqttBounds(gatewaylib.CellTestCase):

    def start_mqtt(self):
        self.sub = None

        def subscribe_first():
            self.sub = self.subscribe(PREFIX + "/+/cmd/result")
        self.start_cell(mqtt=True, before_gateway=subscribe_first)

    def result(self, device, predicate, mark):
        found = self.sub.wait_message("%s/%s/cmd/result" % (PREFIX, device),
                                      gatewaylib.json_predicate(predicate), TIMEOUT, mark)
        self.assertIsNotNone(found, "no result on %s" % device)
        return json.loads(found[1])

    def command_result(self, device, text, predicate=lambda r: True):
        """Publishes `text` until a result comes (the gateway may still be subscribing)."""
        deadline = time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            mark = self.sub.mark()
            self.publish("%s/%s/cmd" % (PREFIX, device), text)
            found = self.sub.wait_message("%s/%s/cmd/result" % (PREFIX, device),
                                          gatewaylib.json_predicate(predicate), 1.0, mark)
            if found is not None:
                return json.loads(found[1])
        self.fail("no result for %s on %s" % (text[:80], device))

    def test_duplicate_keys_are_refused_and_nothing_runs(self):
        self.start_mqtt()
        result = self.command_result("gripper-1", '{"id":10,"op":"stop","op":"reset"}')
        self.assertEqual((result["ok"], result.get("error"), result["id"]), (False, "bad_json", None), result)
        # No reset reached the XEG: it still refuses a move (exception 0x04 before a reset).
        client = self.client()
        self.assert_exception(client.write_registers(0x0630, [1000, 5000, 1], slave=XEG), 0x04)

    def test_huge_commands_are_refused_unread_and_cost_no_memory_or_log(self):
        self.start_mqtt()
        # The gateway answers commands at all (and has subscribed).
        first = self.command_result("gripper-1", json.dumps({"id": "warm-up", "op": "stop"}),
                                    lambda r: r["id"] == "warm-up")
        self.assertTrue(first["ok"], first)
        log_before = os.path.getsize(self.gateway.log_path)
        rss_before = rss_kib(self.gateway.pid)
        # 20 commands of ~900 KB each.
        big = self.path("big-command.json")
        with open(big, "w", encoding="ascii") as f:
            json.dump({"id": "x" * 900000, "op": "stop"}, f)
        mark = self.sub.mark()
        for _ in range(20):
            done = subprocess.run(["mosquitto_pub", "-h", "127.0.0.1", "-p", str(self.mqtt_port), "-q", "1",
                                   "-t", PREFIX + "/gripper-1/cmd", "-f", big],
                                  capture_output=True, timeout=gatewaylib.IO_TIMEOUT)
            self.assertEqual(done.returncode, 0, done.stderr)
        self.result("gripper-1", lambda r: r["error"] == "too_large", mark)
        # A command with a 5000-character id: executed, its id echoed cut to 128.
        long_id = "y" * 5000
        mark = self.sub.mark()
        self.publish(PREFIX + "/gripper-1/cmd", json.dumps({"id": long_id, "op": "stop"}))
        answered = self.result("gripper-1", lambda r: r["id"] == "y" * 128, mark)
        self.assertTrue(answered["ok"], answered)
        too_large = [json.loads(p) for _, p in self.sub.messages(PREFIX + "/gripper-1/cmd/result")
                     if '"too_large"' in p]
        self.assertGreaterEqual(len(too_large), 1)
        self.assertTrue(all(r["id"] is None for r in too_large))
        # Neither the results nor the log carry the payloads; memory did not follow them.
        self.assertLess(os.path.getsize(self.gateway.log_path) - log_before, 200000)
        self.assertLess(rss_kib(self.gateway.pid) - rss_before, 64 * 1024)


class R6Upstream(gatewaylib.CellTestCase):

    def test_malformed_upstream_replies_become_0x04(self):
        self.start_cell(r6=True)
        sock = self.raw()
        request = read_pdu(0x0082, 1)
        sock.sendall(mbap(1, R6, request))
        self.assertEqual(read_frame(sock), (1, R6, bytes.fromhex("03 02 00 02")))
        for i, kind in enumerate(("long_exception", "extra_registers", "byte_count")):
            self.control("r6 malform %s 0x0082" % kind)
            sock.sendall(mbap(10 + i, R6, request))
            self.assertEqual(read_frame(sock), (10 + i, R6, b"\x83\x04"), kind)
        self.control("r6 malform off")
        sock.sendall(mbap(20, R6, request))
        self.assertEqual(read_frame(sock), (20, R6, bytes.fromhex("03 02 00 02")))
        self.assertTrue(self.gateway.wait_line(lambda line: "malformed reply" in line, TIMEOUT))

    def test_a_client_re_selecting_a_counter_does_not_hold_it_forever(self):
        self.start_cell(r6=True)
        holder = self.raw()
        select = struct.pack(">BHHB", 0x10, 0x0883, 2, 4) + struct.pack(">HH", 0, 0)
        holder.sendall(mbap(1, R6, select))
        self.assertEqual(read_frame(holder)[2][:1], b"\x10")
        # The holder re-selects every 200 ms for 4 s; the other client reads the
        # counter block meanwhile and must get its answer within the maximum hold
        # (500 ms by default) plus a margin, not after the holder stops.
        reader = self.raw()
        started = time.monotonic()
        reader.sendall(mbap(2, R6, read_pdu(0x0883, 6)))
        reader.settimeout(0.2)
        answer = None
        transaction = 100
        while time.monotonic() - started < 4.0 and answer is None:
            holder.sendall(mbap(transaction, R6, select))
            self.assertEqual(read_frame(holder)[0], transaction)
            transaction += 1
            try:
                answer = read_frame(reader)
            except socket.timeout:
                pass
        self.assertIsNotNone(answer, "the read waited as long as the holder kept re-selecting")
        waited = time.monotonic() - started
        self.assertEqual(answer[0], 2)
        self.assertEqual(answer[2][:2], b"\x03\x0c", answer)
        self.assertLess(waited, 2.0)

    def test_reads_waiting_on_a_hold_do_not_crowd_out_other_reads(self):
        # A holder re-selects the counter block again and again; three clients
        # pipeline reads of that block, one every 50 ms between them; another reads
        # an unrelated register. With an endless hold the waiting reads filled the
        # queue (32) within 1.6 s and the unrelated reads were refused 0x06. Now
        # each hold lapses after 500 ms: every read gets its registers.
        self.start_cell(r6=True)
        holder, other = self.raw(), self.raw()
        waiters = [self.raw() for _ in range(3)]
        select = struct.pack(">BHHB", 0x10, 0x0883, 2, 4) + struct.pack(">HH", 0, 0)
        holder.sendall(mbap(1, R6, select))
        self.assertEqual(read_frame(holder)[2][:1], b"\x10")
        stop = threading.Event()
        holder_errors = []

        def keep_re_selecting():
            transaction = 100
            while not stop.is_set():
                holder.sendall(mbap(transaction, R6, select))
                frame = read_frame(holder)
                if frame is None or frame[2][:1] != b"\x10":
                    holder_errors.append(frame)
                    return
                transaction += 1
                stop.wait(0.1)

        thread = threading.Thread(target=keep_re_selecting, daemon=True)
        thread.start()
        try:
            sent, worst_other = 0, 0.0
            started = time.monotonic()
            while time.monotonic() - started < 3.0:
                waiters[sent % 3].sendall(mbap(1000 + sent, R6, read_pdu(0x0883, 6)))
                sent += 1
                asked = time.monotonic()
                other.sendall(mbap(sent, R6, read_pdu(0x0082, 1)))
                self.assertEqual(read_frame(other), (sent, R6, bytes.fromhex("03 02 00 02")))
                worst_other = max(worst_other, time.monotonic() - asked)
                # Pacing of the load (one request each 50 ms), not orchestration.
                time.sleep(max(0.0, started + 0.05 * sent - time.monotonic()))
        finally:
            stop.set()
            thread.join(TIMEOUT)
        self.assertEqual(holder_errors, [])
        for i in range(sent):
            frame = read_frame(waiters[i % 3])
            self.assertIsNotNone(frame, "the gateway closed the waiting client")
            self.assertEqual(frame[0], 1000 + i)
            self.assertEqual(frame[2][:2], b"\x03\x0c", "read %d of the held block: %s" % (i, frame[2].hex(" ")))
        # The unrelated reads never waited for the hold.
        self.assertLess(worst_other, 0.5)


def rss_kib(pid):
    with open("/proc/%d/status" % pid, encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS for %d" % pid)


if __name__ == "__main__":
    gatewaylib.main()
