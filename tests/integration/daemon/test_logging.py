"""Log format of the real binary: journald priority prefixes when stderr is the
journal stream named by JOURNAL_STREAM, a human format otherwise."""

import re
import signal
import unittest

import daemon_harness as h

HUMAN = re.compile(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3} \[(trace|debug|info|warning|error|critical)\] .+")
JOURNAL = re.compile(r"^<[2-7]>.+")


class Logging(h.DaemonTestCase, unittest.TestCase):

    def run_until_ready_and_stop(self, env):
        notify = self.notify_socket()
        path = self.config(h.CONFIG_ONE_LINE)
        gateway = self.start(["--config", path, "--log-level", "debug"],
                             env=lambda identity: h.clean_environment(dict(env(identity), NOTIFY_SOCKET=notify.path)))
        notify.wait_for_prefix("READY=1")
        gateway.send(signal.SIGHUP)  # with an unchanged file: an info line
        notify.wait_for_prefix("RELOADING=1")
        notify.wait_for_prefix("READY=1")
        gateway.send(signal.SIGTERM)
        self.assertEqual(gateway.wait_exit(), 0)
        return [line for line in gateway.lines if line is not None]

    def test_journal_stream_gets_priority_prefixes(self):
        lines = self.run_until_ready_and_stop(lambda identity: {"JOURNAL_STREAM": identity})
        self.assertTrue(lines)
        for line in lines:
            self.assertRegex(line, JOURNAL)
        self.assertTrue(any(line.startswith("<6>ready: 1 line, 2 devices, lines 0/1 up, devices 0/2 online, Modbus TCP: ") for line in lines), lines)
        self.assertTrue(any(line.startswith("<7>") for line in lines), lines)  # debug, from --log-level

    def test_journal_stream_of_another_file_means_human_format(self):
        # Inherited from a parent whose stderr was the journal, but ours is not.
        lines = self.run_until_ready_and_stop(lambda identity: {"JOURNAL_STREAM": "1:1"})
        for line in lines:
            self.assertRegex(line, HUMAN)

    def test_no_journal_stream_means_human_format(self):
        lines = self.run_until_ready_and_stop(lambda identity: {})
        for line in lines:
            self.assertRegex(line, HUMAN)
        self.assertTrue(any("[info] ready: 1 line, 2 devices, lines 0/1 up, devices 0/2 online" in line for line in lines), lines)

    def test_config_errors_are_logged_at_error_priority(self):
        path = self.config(h.CONFIG_BROKEN)
        gateway = self.start(["--config", path],
                             env=lambda identity: h.clean_environment({"JOURNAL_STREAM": identity}))
        self.assertEqual(gateway.wait_exit(), 2)
        self.assertIn("<3>%s:3:3: gateway.colour: " % path, gateway.stderr_text())


if __name__ == "__main__":
    Logging.binary, Logging.config_dir = h.parse_arguments()
    unittest.main()
