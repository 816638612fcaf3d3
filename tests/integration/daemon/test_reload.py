"""SIGHUP on the real binary: a broken configuration is rejected and the old one
stays; a valid one is taken."""

import os
import signal
import socket
import unittest

import daemon_harness as h


class Reload(h.DaemonTestCase, unittest.TestCase):

    def test_broken_then_valid_reload(self):
        notify = self.notify_socket()
        path = self.config(h.CONFIG_ONE_LINE)
        gateway = self.start(["--config", path], env=h.clean_environment({"NOTIFY_SOCKET": notify.path}))
        ready = notify.wait_for_prefix("READY=1")
        self.assertTrue(ready.startswith("READY=1\nSTATUS=1 line, 2 devices, lines 0/1 up, devices 0/2 online" + ", Modbus TCP: "), ready)

        # A broken file: RELOADING=1, every diagnostic logged, READY=1 again with
        # the old configuration, and the process keeps running.
        h.write_file(self.tmp, os.path.basename(path), h.CONFIG_BROKEN)
        gateway.send(signal.SIGHUP)
        reloading = notify.wait_for_prefix("RELOADING=1")
        self.assertRegex(reloading, r"^RELOADING=1\nMONOTONIC_USEC=\d+$")
        ready = notify.wait_for_prefix("READY=1")
        self.assertTrue(ready.startswith("READY=1\nSTATUS=last reload rejected (see the log), 1 line, 2 devices, lines 0/1 up, devices 0/2 online" + ", Modbus TCP: "), ready)
        gateway.wait_for_log("%s:3:3: gateway.colour: " % path)
        gateway.wait_for_log("%s:9:11: lines[0].baud: " % path)
        gateway.wait_for_log("configuration reload rejected: 2 problems in %s" % path)
        self.assertTrue(gateway.running())

        # A valid, changed file is taken.
        h.write_file(self.tmp, os.path.basename(path), h.CONFIG_TWO_LINES)
        gateway.send(signal.SIGHUP)
        notify.wait_for_prefix("RELOADING=1")
        ready = notify.wait_for_prefix("READY=1")
        self.assertTrue(ready.startswith("READY=1\nSTATUS=2 lines, 3 devices, lines 0/2 up, devices 0/3 online" + ", Modbus TCP: "), ready)
        gateway.wait_for_log("configuration reloaded from %s (2 lines, 3 devices, MQTT disabled)" % path)

        gateway.send(signal.SIGTERM)
        notify.wait_for_prefix("STOPPING=1")
        self.assertEqual(gateway.wait_exit(), 0)

    def test_a_listen_address_in_use_rejects_the_whole_reload(self):
        notify = self.notify_socket()
        path = self.config(h.CONFIG_ONE_LINE)
        gateway = self.start(["--config", path], env=h.clean_environment({"NOTIFY_SOCKET": notify.path}))
        notify.wait_for_prefix("READY=1")
        port = h._PORT["port"]
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as blocker:
            blocker.bind(("127.0.0.1", 0))
            blocker.listen()
            busy = blocker.getsockname()[1]
            # A second line and a second listener whose port is taken: nothing of it applies.
            h.write_file(self.tmp, os.path.basename(path), h.CONFIG_TWO_LINES.replace(
                '["127.0.0.1:%d"]' % port, '["127.0.0.1:%d", "127.0.0.1:%d"]' % (port, busy)))
            gateway.send(signal.SIGHUP)
            notify.wait_for_prefix("RELOADING=1")
            ready = notify.wait_for_prefix("READY=1")
            self.assertTrue(ready.startswith("READY=1\nSTATUS=last reload rejected: Modbus TCP: cannot listen on "
                                             "127.0.0.1:%d (bind failed: Address already in use)" % busy), ready)
            self.assertIn(", 1 line, 2 devices, ", ready)
            gateway.wait_for_log("configuration reload rejected: Modbus TCP server cannot apply it: Modbus TCP: "
                                 "cannot listen on 127.0.0.1:%d" % busy)
            socket.create_connection(("127.0.0.1", port), timeout=h.TIMEOUT).close()  # the old listener stays

        # The port is free again: the same file is taken whole.
        gateway.send(signal.SIGHUP)
        notify.wait_for_prefix("RELOADING=1")
        ready = notify.wait_for_prefix("READY=1")
        self.assertTrue(ready.startswith("READY=1\nSTATUS=2 lines, 3 devices, "), ready)
        gateway.wait_for_log("Modbus TCP: listening on 127.0.0.1:%d" % busy)
        socket.create_connection(("127.0.0.1", busy), timeout=h.TIMEOUT).close()
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)

    def test_reload_with_the_file_gone(self):
        notify = self.notify_socket()
        path = self.config(h.CONFIG_ONE_LINE)
        gateway = self.start(["--config", path], env=h.clean_environment({"NOTIFY_SOCKET": notify.path}))
        notify.wait_for_prefix("READY=1")
        os.unlink(path)
        gateway.send(signal.SIGHUP)
        notify.wait_for_prefix("RELOADING=1")
        notify.wait_for_prefix("READY=1")
        gateway.wait_for_log(path + ": cannot open the configuration file")
        self.assertTrue(gateway.running())
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)

    def test_log_level_follows_the_reloaded_file_unless_overridden(self):
        quiet = h.CONFIG_ONE_LINE.replace("log_level: info", "log_level: error")
        verbose = h.CONFIG_ONE_LINE.replace("log_level: info", "log_level: debug")
        for override, expect_info in ((None, True), ("error", False)):
            with self.subTest(override=override):
                notify = h.NotifySocket(self.tmp + "/" + (override or "none"))
                self.sockets.append(notify)
                path = self.config(quiet, "level-%s.yaml" % (override or "none"))
                args = ["--config", path] + (["--log-level", override] if override else [])
                gateway = self.start(args, env=h.clean_environment({"NOTIFY_SOCKET": notify.path}))
                notify.wait_for_prefix("READY=1")
                h.write_file(self.tmp, os.path.basename(path), verbose)
                gateway.send(signal.SIGHUP)
                notify.wait_for_prefix("READY=1")
                gateway.send(signal.SIGTERM)
                self.assertEqual(gateway.wait_exit(), 0)
                self.assertEqual("configuration reloaded" in gateway.stderr_text(), expect_info,
                                 gateway.stderr_text())

    def setUp(self):
        super().setUp()
        for sub in ("none", "error"):
            os.mkdir(os.path.join(self.tmp, sub))


if __name__ == "__main__":
    Reload.binary, Reload.config_dir = h.parse_arguments()
    unittest.main()
