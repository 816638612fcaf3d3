"""A serial device server in "TCP server" (transparent) mode, on loopback, in front of
one of the simulator's pseudo-terminals: what a Moxa NPort or a USR-TCP232 does for a
real RS-485 line. It accepts one client at a time (like most device servers; a second
one is closed at once) and forwards bytes both ways as they come.

For the tests of issue 27 it can misbehave on purpose, one reply at a time:
  split   every reply leaves in two TCP segments, `split_gap` apart
  merge   the next reply is held and leaves in one segment with the reply after it
  late    the next reply is held and leaves just after the client's next request
(a reply may come off the pseudo-terminal in several reads, the simulator pacing it at
the wire's rate: everything the line sends is held until the client's next request)
  cut     the next reply: its first half, then the connection is closed
and refuse() / listen() close and reopen the listening socket (connections refused
meanwhile). Python 3 standard library only; one thread; every wait bounded."""

import os
import select
import socket
import threading
import time

import simlib


class DeviceServer:

    def __init__(self, pty_path, port=0):
        self.pty_path = pty_path
        self.port = port
        self.pty = simlib.open_raw(pty_path)
        self.listener = None
        self.client = None
        self.mode = None          # None, "split", "merge", "late", "cut"
        self.split_gap = 0.002
        self.held = b""
        self.asked_again = False  # merge: the client sent its next request since the hold
        self.accepted = 0         # connections taken
        self.turned_away = 0      # second clients closed at once
        self.accepted_at = []     # time.monotonic() of each accept
        self._lock = threading.Lock()
        self._stop = False
        self.listen()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    # -- control (from the test's thread) --------------------------------------------

    def listen(self):
        with self._lock:
            if self.listener is not None:
                return
            listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            listener.bind(("127.0.0.1", self.port))
            listener.listen(4)
            self.port = listener.getsockname()[1]
            self.listener = listener

    def refuse(self):
        """Closes the listener and the client: connections are refused until listen()."""
        with self._lock:
            if self.listener is not None:
                self.listener.close()
                self.listener = None
            self._drop_client()

    def set_mode(self, mode):
        with self._lock:
            self.mode = mode
            self.held = b""
            self.asked_again = False

    def close(self):
        self._stop = True
        self._thread.join(timeout=5)
        with self._lock:
            if self.listener is not None:
                self.listener.close()
                self.listener = None
            self._drop_client()
        os.close(self.pty)

    # -- the loop ------------------------------------------------------------------------

    def _drop_client(self):
        if self.client is not None:
            self.client.close()
            self.client = None

    def _run(self):
        while not self._stop:
            with self._lock:
                watched = [self.pty] + [s for s in (self.listener, self.client) if s is not None]
            readable, _, _ = select.select(watched, [], [], 0.05)
            with self._lock:
                for item in readable:
                    if item is self.listener and self.listener is not None:
                        self._accept()
                    elif item is self.client and self.client is not None:
                        self._from_client()
                    elif item == self.pty:
                        self._from_line()

    def _client_closed(self):
        """The client's end of file is already here (read without taking it)."""
        try:
            return self.client.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
        except BlockingIOError:
            return False
        except OSError:
            return True

    def _accept(self):
        conn, _ = self.listener.accept()
        if self.client is not None and self._client_closed():
            # The gateway closed and connected again within one select() round: the
            # close came first (its end of file is queued), so this is no second client.
            self._drop_client()
        if self.client is not None:
            # One client at a time, as most device servers in TCP server mode.
            conn.close()
            self.turned_away += 1
            return
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.client = conn
        self.accepted += 1
        self.accepted_at.append(time.monotonic())

    def _from_client(self):
        try:
            data = self.client.recv(4096)
        except OSError:
            data = b""
        if not data:
            self._drop_client()
            return
        if self.mode == "late" and self.held:
            # The held reply leaves right after the next request arrived.
            self.client.sendall(self.held)
            self.held = b""
            self.mode = None
        elif self.mode == "merge" and self.held:
            self.asked_again = True  # the held reply goes out with the first of the next
        os.write(self.pty, data)

    def _from_line(self):
        try:
            data = os.read(self.pty, 4096)
        except BlockingIOError:
            return
        if self.client is None or not data:
            return
        mode = self.mode
        if mode == "split" and len(data) > 1:
            half = len(data) // 2
            self.client.sendall(data[:half])
            time.sleep(self.split_gap)
            self.client.sendall(data[half:])
        elif mode == "merge" and self.asked_again:
            self.client.sendall(self.held + data)
            self.held = b""
            self.asked_again = False
            self.mode = None
        elif mode in ("merge", "late"):
            self.held += data
        elif mode == "cut":
            self.client.sendall(data[:max(1, len(data) // 2)])
            self._drop_client()
            self.mode = None
        else:
            self.client.sendall(data)
