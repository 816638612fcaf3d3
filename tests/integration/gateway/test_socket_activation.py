"""Socket activation (issue 15, docs/service.md "Socket activation"): the real gateway
started by systemd-socket-activate on a loopback port takes its Modbus TCP listener
from LISTEN_FDS (matched by address, or by a FileDescriptorName= that is the port of a
modbus_tcp.listen entry) and serves a unit to pymodbus, including the connection that
activated it; a socket that matches no entry, or an entry left without a socket, stop
the start with exit status 2 and a message that says what to change; a reload keeps
an inherited listener, and one that drops it logs that the socket stays open.

systemd-socket-activate listens, waits for the first connection, then execs the
gateway in its own process (same PID), as systemd does for a socket unit."""

import re
import shutil
import signal

import gatewaylib

XEG = 1
XEG_MODEL = 0x0600


class SocketActivation(gatewaylib.CellTestCase):

    def setUp(self):
        super().setUp()
        if shutil.which("systemd-socket-activate") is None:
            self.fail("systemd-socket-activate (package systemd) is needed")

    def activate(self, socket_port=None, fdname=None, listen=None):
        """The cell with the gateway under systemd-socket-activate listening on
        127.0.0.1:socket_port (default: the configured Modbus TCP port), the socket
        named fdname(configured port) when given, modbus_tcp.listen replaced by
        listen(configured port) when given; returns once the activator listens."""
        def launcher():
            self.socket_port = socket_port or self.tcp_port
            command = ["systemd-socket-activate", "-l", "127.0.0.1:%d" % self.socket_port]
            if fdname is not None:
                command.append("--fdname=%s" % fdname(self.tcp_port))
            if listen is not None:
                self.set_listen(listen(self.tcp_port))
            return command
        self.start_cell(launcher=launcher, wait_ready=False)
        listening = "Listening on 127.0.0.1:%d" % self.socket_port
        if self.gateway.wait_line(lambda line: listening in line, gatewaylib.START_TIMEOUT) is None:
            self.fail("systemd-socket-activate did not listen:\n" + self.gateway.text())

    def client_on(self, port):
        client = gatewaylib.ModbusTcpClient("127.0.0.1", port=port, timeout=gatewaylib.IO_TIMEOUT, retries=0)
        # The connection activates the gateway: it waits in the socket's backlog until
        # the gateway accepts it.
        self.assertTrue(client.connect(), "pymodbus cannot connect to the activation socket")
        self.clients.append(client)
        return client

    def assert_serves(self, client):
        self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A20])

    def expect_refused_start(self, *fragments):
        code = self.gateway.wait_exit(gatewaylib.START_TIMEOUT)
        self.assertEqual(code, 2, self.gateway.text())
        for fragment in fragments:
            self.assertIn(fragment, self.gateway.text())
        self.assertNotIn("ready:", self.gateway.text())

    def test_socket_matched_by_address_serves_modbus_tcp(self):
        self.activate()
        client = self.client_on(self.socket_port)
        self.wait_ready()
        self.assertIn("Modbus TCP: listening on 127.0.0.1:%d (socket passed by systemd)" % self.tcp_port,
                      self.gateway.text())
        self.assert_serves(client)          # the connection that started it
        self.assert_serves(self.client())   # and a new one

    def test_socket_matched_by_fdname_serves_the_entry_with_that_port(self):
        other = gatewaylib.free_port()
        self.activate(socket_port=other, fdname=str)
        client = self.client_on(other)
        self.wait_ready()
        self.assert_serves(client)
        self.assertFalse(gatewaylib.wait_port(self.tcp_port, 0.5), "the configured port must not be bound")

    def test_socket_matching_no_entry_is_a_start_up_error(self):
        other = gatewaylib.free_port()
        self.activate(socket_port=other, fdname=lambda port: "modbus")
        self.client_on(other)
        self.expect_refused_start(
            "cannot start: socket activation: fd 3 (FileDescriptorName=modbus, listening on 127.0.0.1:%d) matches "
            "no modbus_tcp.listen entry [127.0.0.1:%d]" % (other, self.tcp_port))

    def test_entry_without_a_socket_is_a_start_up_error(self):
        second = gatewaylib.free_port()
        self.activate(listen=lambda port: ["127.0.0.1:%d" % port, "127.0.0.1:%d" % second])
        self.client_on(self.socket_port)
        self.expect_refused_start(
            "modbus_tcp.listen entry 127.0.0.1:%d has no socket, while the service manager passed one; "
            "add ListenStream=127.0.0.1:%d" % (second, second))

    def test_reload_keeps_the_inherited_listener_and_warns_when_it_is_dropped(self):
        self.activate()
        client = self.client_on(self.socket_port)
        self.wait_ready()
        # Kept: another listener added beside it.
        second = gatewaylib.free_port()
        self.reload_with_listen(["127.0.0.1:%d" % self.tcp_port, "127.0.0.1:%d" % second])
        self.assert_serves(client)
        self.assert_serves(self.client())
        self.assertTrue(gatewaylib.wait_port(second, gatewaylib.IO_TIMEOUT))
        # Dropped: no longer accepted from, and the log says why clients hang.
        self.reload_with_listen(["127.0.0.1:%d" % second])
        warning = "no longer accepting on 127.0.0.1:%d; its socket came from systemd and stays open" % self.tcp_port
        self.assertIsNotNone(self.gateway.wait_line(lambda line: warning in line, gatewaylib.IO_TIMEOUT),
                             self.gateway.text())
        self.assert_serves(client)  # open connections are not closed by a listener change

    # -- helpers ---------------------------------------------------------------------

    def set_listen(self, addresses):
        """modbus_tcp.listen of the configuration file becomes addresses."""
        with open(self.config_path, encoding="utf-8") as f:
            text = f.read()
        text, count = re.subn(r"listen: \[[^\]]*\]", "listen: [%s]" % ", ".join('"%s"' % a for a in addresses),
                              text, count=1)
        self.assertEqual(count, 1)
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(text)

    def reload_with_listen(self, addresses):
        start = len(self.gateway.lines)
        self.set_listen(addresses)
        self.gateway.signal(signal.SIGHUP)
        found = self.gateway.wait_line(lambda line: "configuration reloaded" in line, gatewaylib.IO_TIMEOUT, start)
        self.assertIsNotNone(found, self.gateway.text())


if __name__ == "__main__":
    gatewaylib.main()
