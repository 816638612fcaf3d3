"""The command line that runs a program built for this machine or, in a cross build, for
the target under its emulator (docs/build.md, "Cross builds").

FIELDBRIDGE_TEST_EMULATOR holds the emulator's command (e.g. `qemu-aarch64 -L
/var/cache/fieldbridge/sysroot/bookworm-arm64`); ctest sets it from
CMAKE_CROSSCOMPILING_EMULATOR for the tests that start the cross-built daemon. Unset or
empty: the program runs as it is. qemu-user runs the program in its own process, so
the PID a test signals, and the one the daemon reports to systemd, is the program's."""

import os
import shlex


def emulator():
    """The emulator's argv, [] when the programs are this machine's."""
    return shlex.split(os.environ.get("FIELDBRIDGE_TEST_EMULATOR", ""))


def emulated():
    return bool(emulator())


def target_command(binary, *args):
    """argv that runs binary with args, under the emulator when there is one."""
    return emulator() + [binary] + list(args)


def target_file(path):
    """Whether a file the process maps (/proc/<pid>/maps) is one of the program's own:
    under the emulator, the program's libraries come from the root given with -L, while
    the emulator maps this machine's libraries for itself (qemu-user links GnuTLS)."""
    argv = emulator()
    if "-L" not in argv[:-1]:
        return True
    root = argv[argv.index("-L") + 1].rstrip("/") + "/"
    return path.startswith(root)
