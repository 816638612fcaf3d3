"""sd_notify(3) protocol of the real binary: READY=1, STATUS=, WATCHDOG=1,
STOPPING=1, and a silent no-op without NOTIFY_SOCKET."""

import signal
import unittest

import daemon_harness as h


class Notify(h.DaemonTestCase, unittest.TestCase):

    def start_notified(self, extra_env=None, watchdog_pid_is_self=False, config=h.CONFIG_ONE_LINE):
        notify = self.notify_socket()
        env = {"NOTIFY_SOCKET": notify.path}
        env.update(extra_env or {})
        gateway = self.start(["--config", self.config(config)], env=h.clean_environment(env),
                             watchdog_pid_is_self=watchdog_pid_is_self)
        return notify, gateway

    def test_ready_status_and_stop_on_sigterm(self):
        notify, gateway = self.start_notified()
        ready = notify.wait_for_prefix("READY=1")
        self.assertTrue(ready.startswith("READY=1\nSTATUS=1 line, 2 devices, lines 0/1 up, devices 0/2 online, Modbus TCP: "), ready)
        self.assertTrue(gateway.running())
        gateway.send(signal.SIGTERM)
        stopping = notify.wait_for_prefix("STOPPING=1")
        self.assertTrue(stopping.startswith("STOPPING=1\nSTATUS=stopping"), stopping)
        self.assertEqual(gateway.wait_exit(), 0)
        gateway.wait_for_log("stopping: SIGTERM received")
        # Nothing but what the protocol allows, and no watchdog when not asked for.
        for message in notify.messages:
            self.assertRegex(message, r"^(READY|STATUS|STOPPING)=")

    def test_sigint_stops_too(self):
        notify, gateway = self.start_notified()
        notify.wait_for_prefix("READY=1")
        gateway.send(signal.SIGINT)
        notify.wait_for_prefix("STOPPING=1")
        self.assertEqual(gateway.wait_exit(), 0)

    def test_status_before_ready_says_starting(self):
        notify, gateway = self.start_notified()
        notify.wait_for_prefix("READY=1")
        first_status = next(m for m in notify.messages if m.startswith("STATUS="))
        self.assertTrue(first_status.startswith("STATUS=starting"), first_status)
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)

    def test_watchdog_pings_at_half_the_interval(self):
        # 200 ms watchdog: a ping every 100 ms.
        notify, gateway = self.start_notified({"WATCHDOG_USEC": "200000"}, watchdog_pid_is_self=True)
        notify.wait_for_prefix("READY=1")
        for _ in range(3):
            notify.wait_for(lambda m: m == "WATCHDOG=1", "WATCHDOG=1")
        gateway.wait_for_log("systemd watchdog enabled: pinging every 100 ms")
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)

    def test_watchdog_for_another_pid_is_ignored(self):
        # sd_watchdog_enabled(3): WATCHDOG_PID names the process meant; 1 is not us.
        notify, gateway = self.start_notified({"WATCHDOG_USEC": "200000", "WATCHDOG_PID": "1"})
        notify.wait_for_prefix("READY=1")
        gateway.send(signal.SIGTERM)
        notify.wait_for_prefix("STOPPING=1")
        self.assertEqual(gateway.wait_exit(), 0)
        notify.drain()
        self.assertNotIn("WATCHDOG=1", notify.messages)

    def test_without_notify_socket_everything_is_a_no_op(self):
        gateway = self.start(["--config", self.config(h.CONFIG_ONE_LINE)])
        gateway.wait_for_log("ready: 1 line, 2 devices")
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)
        self.assertNotIn("cannot notify", gateway.stderr_text())

    def test_unreachable_notify_socket_is_logged_not_fatal(self):
        missing = self.tmp + "/no-such-manager.sock"
        gateway = self.start(["--config", self.config(h.CONFIG_ONE_LINE)],
                             env=h.clean_environment({"NOTIFY_SOCKET": missing}))
        gateway.wait_for_log("cannot notify the service manager")
        gateway.wait_for_log("ready: ")
        self.assertTrue(gateway.running())
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)


if __name__ == "__main__":
    Notify.binary, Notify.config_dir = h.parse_arguments()
    unittest.main()
