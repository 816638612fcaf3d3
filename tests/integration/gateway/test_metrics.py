"""Prometheus metrics (issue 15 item 3, docs/service.md "Metrics"): the real gateway
on the simulated cell with metrics_http on a free loopback port. A scrape after
Modbus TCP traffic shows the line, device, Modbus TCP, upstream, MQTT, reload and
build families with counters that moved, a transaction-duration histogram whose count
is the line's transactions, and passes `promtool check metrics` (Debian's
prometheus package). Also: 404/405, the reload counter, a rebind when the address
changes on reload, a clear start-up error when the port is taken, libmicrohttpd
(with GnuTLS) mapped only once metrics_http is configured, and clients that trickle
header bytes neither hold the endpoint nor stop it for good (issue 24 item 1)."""

import re
import shutil
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request

import gatewaylib
import simlib

XEG = 1
XEG_MODEL = 0x0600
NO_SUCH_UNIT = 99
CONTENT_TYPE = "text/plain; version=0.0.4; charset=utf-8"

_SAMPLE = re.compile(r'^([a-zA-Z_:][a-zA-Z0-9_:]*)(?:\{(.*)\})? (\S+)$')
_LABEL = re.compile(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"')


def parse(text):
    """[(name, {label: value}, float)] of every sample line."""
    samples = []
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        found = _SAMPLE.match(line)
        if found is None:
            raise AssertionError("not a sample line: %r" % line)
        samples.append((found.group(1), dict(_LABEL.findall(found.group(2) or "")), float(found.group(3))))
    return samples


def values(samples, name, **labels):
    return [v for n, l, v in samples if n == name and all(l.get(k) == w for k, w in labels.items())]


class Metrics(gatewaylib.CellTestCase):

    def url(self, path="/metrics", port=None):
        return "http://127.0.0.1:%d%s" % (port or self.metrics_port, path)

    def scrape(self, port=None):
        with urllib.request.urlopen(self.url(port=port), timeout=gatewaylib.IO_TIMEOUT) as response:
            self.assertEqual(response.status, 200)
            self.assertEqual(response.headers["Content-Type"], CONTENT_TYPE)
            return response.read().decode("utf-8")

    def one(self, samples, name, **labels):
        found = values(samples, name, **labels)
        self.assertEqual(len(found), 1, "%s%r: %r" % (name, labels, found))
        return found[0]

    def wait_sample(self, name, predicate, what, **labels):
        """Scrapes until the one sample name{labels} satisfies predicate (bounded)."""
        def check():
            found = values(parse(self.scrape()), name, **labels)
            return len(found) == 1 and predicate(found[0])
        self.assertTrue(simlib.wait_until(check, gatewaylib.START_TIMEOUT, interval=0.1), what)

    def test_scrape_after_traffic_has_every_family_and_passes_promtool(self):
        if shutil.which("promtool") is None:
            self.fail("promtool (Debian package prometheus) is needed")
        self.start_cell(r6=True, mqtt=True, metrics=True)
        client = self.client()
        for _ in range(5):
            self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A20])
        refused = client.read_holding_registers(0, count=1, slave=NO_SUCH_UNIT)
        self.assertTrue(refused.isError(), refused)
        self.wait_sample("fieldbridge_mqtt_connected", lambda v: v == 1, "MQTT never shown connected")
        self.wait_sample("fieldbridge_upstream_up", lambda v: v == 1, "the R6 link never shown up", upstream="r6")

        body = self.scrape()
        samples = parse(body)
        # promtool: syntax and the naming lints (counters _total, base units, HELP).
        checked = subprocess.run(["promtool", "check", "metrics"], input=body, capture_output=True, text=True,
                                 timeout=gatewaylib.IO_TIMEOUT)
        self.assertEqual((checked.returncode, checked.stdout + checked.stderr), (0, ""), body)
        # One HELP/TYPE per family.
        types = [line.split()[2] for line in body.splitlines() if line.startswith("# TYPE ")]
        self.assertEqual(len(types), len(set(types)), "a family written twice")

        self.assertEqual(self.one(samples, "fieldbridge_build_info"), 1)
        self.assertTrue(values(samples, "fieldbridge_build_info", version=self.version()))
        for line in ("line-a", "line-b"):
            self.assertEqual(self.one(samples, "fieldbridge_line_up", line=line), 1)
            requests = self.one(samples, "fieldbridge_line_requests_total", line=line)
            self.assertGreater(requests, 0, line)
            self.assertGreater(self.one(samples, "fieldbridge_line_transmitted_bytes_total", line=line), 0)
            self.assertGreater(self.one(samples, "fieldbridge_line_received_bytes_total", line=line), 0)
            self.assertGreater(self.one(samples, "fieldbridge_line_busy_seconds_total", line=line), 0)
            # Every transaction that went on the wire is one histogram sample.
            written = sum(self.one(samples, "fieldbridge_line_%s_total" % what, line=line)
                          for what in ("replies", "timeouts", "broadcasts"))
            count = self.one(samples, "fieldbridge_line_transaction_duration_seconds_count", line=line)
            self.assertEqual(count, written, line)
            self.assertEqual(self.one(samples, "fieldbridge_line_transaction_duration_seconds_bucket",
                                      line=line, le="+Inf"), count)
            self.assertGreater(self.one(samples, "fieldbridge_line_transaction_duration_seconds_sum", line=line), 0)
        gripper = {"line": "line-a", "device": "gripper-1", "unit": "1"}
        self.assertEqual(self.one(samples, "fieldbridge_device_online", **gripper), 1)
        self.assertGreater(sum(values(samples, "fieldbridge_device_requests_total", **gripper)), 0)
        for cls in ("command", "on_demand", "poll"):
            self.one(samples, "fieldbridge_device_queue_depth", **gripper, **{"class": cls})
            self.one(samples, "fieldbridge_device_queue_wait_seconds_count", **gripper, **{"class": cls})
        self.assertEqual(self.one(samples, "fieldbridge_modbus_tcp_clients"), 1)
        self.assertEqual(self.one(samples, "fieldbridge_modbus_tcp_requests_total"), 6)
        self.assertEqual(self.one(samples, "fieldbridge_modbus_tcp_exceptions_total",
                                  code="0x%02X" % refused.exception_code), 1)
        self.assertEqual(len(values(samples, "fieldbridge_modbus_tcp_exceptions_total")), 1, "only codes sent")
        self.assertEqual(self.one(samples, "fieldbridge_modbus_tcp_unknown_unit_total"), 1)
        self.assertEqual(self.one(samples, "fieldbridge_upstream_link_state", upstream="r6", state="up"), 1)
        self.assertGreater(self.one(samples, "fieldbridge_mqtt_published_total"), 0)
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="ok"), 0)

        # Counters move between scrapes (the lines keep polling), and scrapes are counted.
        scrapes = self.one(samples, "fieldbridge_metrics_scrapes_total")
        self.wait_sample("fieldbridge_line_requests_total",
                         lambda v: v > self.one(samples, "fieldbridge_line_requests_total", line="line-a"),
                         "line-a's requests did not grow", line="line-a")
        self.assertGreater(self.one(parse(self.scrape()), "fieldbridge_metrics_scrapes_total"), scrapes)

    def test_other_paths_are_404_and_other_methods_405(self):
        self.start_cell(metrics=True)
        with self.assertRaises(urllib.error.HTTPError) as caught:
            urllib.request.urlopen(self.url("/"), timeout=gatewaylib.IO_TIMEOUT)
        self.assertEqual(caught.exception.code, 404)
        with self.assertRaises(urllib.error.HTTPError) as caught:
            urllib.request.urlopen(urllib.request.Request(self.url(), data=b"x", method="POST"),
                                   timeout=gatewaylib.IO_TIMEOUT)
        self.assertEqual(caught.exception.code, 405)
        self.assertEqual(caught.exception.headers["Allow"], "GET, HEAD")

    def test_reloads_are_counted_and_a_new_address_is_rebound(self):
        self.start_cell(metrics=True)
        self.reload("configuration reloaded")
        samples = parse(self.scrape())
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="ok"), 1)
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="rejected"), 0)

        with open(self.config_path, encoding="utf-8") as f:
            good = f.read()
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(good + "no_such_section: 1\n")
        self.reload("configuration reload rejected")
        samples = parse(self.scrape())
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="ok"), 1)
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="rejected"), 1)

        old = self.metrics_port
        new = gatewaylib.free_port()
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(good.replace("127.0.0.1:%d" % old, "127.0.0.1:%d" % new))
        self.reload("configuration reloaded")
        samples = parse(self.scrape(port=new))
        self.assertEqual(self.one(samples, "fieldbridge_reloads_total", result="ok"), 2)
        self.assertFalse(gatewaylib.wait_port(old, 0.5), "the old metrics address still listens")

    def test_metrics_port_in_use_stops_the_start_with_advice(self):
        blocker = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.addCleanup(blocker.close)

        def occupy():
            blocker.bind(("127.0.0.1", self.metrics_port))
            blocker.listen(1)
        self.start_cell(metrics=True, before_gateway=occupy, wait_ready=False)
        code = self.gateway.wait_exit(gatewaylib.START_TIMEOUT)
        self.assertEqual(code, 1, self.gateway.text())
        self.assertIn("cannot start metrics HTTP endpoint: metrics HTTP: cannot listen on 127.0.0.1:%d (bind failed"
                      % self.metrics_port, self.gateway.text())
        self.assertIn("set metrics_http.listen to a free port", self.gateway.text())
        self.assertNotIn("ready:", self.gateway.text())

    def test_libmicrohttpd_and_gnutls_are_loaded_only_with_metrics_http(self):
        # Issue 14 item 6: the library is loaded with dlopen() when the endpoint starts
        # (docs/dependencies.md), so a gateway without metrics_http maps neither it
        # nor the GnuTLS it brings; a reload that adds the section loads it.
        self.start_cell()
        self.assertEqual(self.mapped_libraries("libmicrohttpd", "libgnutls"), set())
        self.metrics_port = gatewaylib.free_port()
        with open(self.config_path, "a", encoding="utf-8") as f:
            f.write(gatewaylib.METRICS_CONFIG.format(metrics_port=self.metrics_port))
        self.reload("configuration reloaded")
        self.assertIn("fieldbridge_build_info", self.scrape())
        self.assertEqual(self.mapped_libraries("libmicrohttpd", "libgnutls"), {"libmicrohttpd", "libgnutls"})

    def test_trickling_clients_are_cut_and_the_endpoint_serves_again_once_they_left(self):
        # Issue 24 item 1: 16 connections (4 addresses, 4 each: the per-address bound
        # lets them all in up to the limit of 8) send one header byte every 3 s for
        # 15 s. They keep the connections busy, not idle, so only the request-header
        # deadline (5 s) frees the slots; once they have closed, a scrape is answered.
        self.start_cell(metrics=True)
        trickling = []
        for i in range(16):
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.bind(("127.0.0.%d" % (2 + i % 4), 0))
            sock.connect(("127.0.0.1", self.metrics_port))
            self.clients.append(sock)
            trickling.append(sock)
        header = b"GET /metrics HTTP/1.1\r\nHost: x\r\n"
        cut = set()
        started = time.monotonic()
        for step in range(5):  # 0, 3, 6, 9, 12 s; the last pause ends at 15 s
            for sock in trickling:
                if sock in cut:
                    continue
                try:
                    sock.sendall(header[step:step + 1])
                except OSError:
                    cut.add(sock)
            pause_end = started + 3.0 * (step + 1)
            while time.monotonic() < pause_end:
                for sock in trickling:
                    if sock not in cut and gatewaylib.closed_by_server(sock, timeout=0.01):
                        cut.add(sock)
                time.sleep(0.1)
        self.assertEqual(len(cut), 16, "trickling connections still open after 15 s")
        for sock in trickling:
            sock.close()
        # Served again at once (bounded: the scrape's own 5 s timeout).
        self.assertIn("fieldbridge_build_info", self.scrape())
        self.assertIn("fieldbridge_build_info", self.scrape())

    def test_one_address_cannot_take_every_connection(self):
        self.start_cell(metrics=True)
        for _ in range(16):
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.bind(("127.0.0.2", 0))
            sock.connect(("127.0.0.1", self.metrics_port))
            sock.sendall(b"G")
            self.clients.append(sock)
        # A scrape from another address while they hold what they were given.
        self.assertIn("fieldbridge_build_info", self.scrape())

    # -- helpers ---------------------------------------------------------------------

    def mapped_libraries(self, *prefixes):
        """Which of the file name prefixes the gateway process maps (/proc/<pid>/maps); under
        an emulator, of the files of the gateway's root (emulation.target_file)."""
        with open("/proc/%d/maps" % self.gateway.pid, encoding="utf-8") as f:
            paths = [line.split()[-1] for line in f if "/" in line]
        names = {path.rsplit("/", 1)[-1] for path in paths if gatewaylib.target_file(path)}
        return {prefix for prefix in prefixes if any(name.startswith(prefix + ".so") for name in names)}

    def reload(self, expected):
        start = len(self.gateway.lines)
        self.gateway.signal(signal.SIGHUP)
        found = self.gateway.wait_line(lambda line: expected in line, gatewaylib.IO_TIMEOUT, start)
        self.assertIsNotNone(found, "no %r after SIGHUP:\n%s" % (expected, self.gateway.text()))

    def version(self):
        done = subprocess.run(gatewaylib.target_command(gatewaylib.GATEWAY, "--version"), capture_output=True, text=True,
                              timeout=gatewaylib.IO_TIMEOUT)
        return done.stdout.split()[-1]


if __name__ == "__main__":
    gatewaylib.main()
