// A Modbus-RTU slave served by libmodbus itself (modbus_receive / modbus_reply), on a
// pseudo-terminal: an implementation of the protocol independent of fieldbridge's
// codecs, for the generic device's function codes (0x11 report server ID, 0x16 mask
// write, 0x17 read/write multiple registers) in test_generic_functions.py.
//
//   fb_test_libmodbus_slave LINK ADDRESS
//
// Creates a pseudo-terminal, links LINK to its slave side (the gateway opens it as
// its line's port), prints "ready" and serves holding registers 0x0000-0x00FF, each
// starting at its own address, as bus address ADDRESS until killed. One register is
// special: an FC03 read starting at 0x00F0 is answered with a well-formed frame (its
// address, a good CRC) that carries one register whatever was asked, the reply "whose
// length does not fit the request" of issue 24 item 10.
#include <fcntl.h>
#include <modbus/modbus.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

constexpr int holding_count = 0x100;
constexpr int misfit_address = 0x00F0;

int fail(const char* what) {
    std::fprintf(stderr, "fb_test_libmodbus_slave: %s: %s\n", what, std::strerror(errno));
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: fb_test_libmodbus_slave LINK ADDRESS\n");
        return 2;
    }
    const std::string link = argv[1];
    const int address = std::atoi(argv[2]);
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return fail("posix_openpt");
    const char* slave_name = ptsname(master);
    if (slave_name == nullptr) return fail("ptsname");
    // Held open here too, so the master never reads EIO before the gateway opens it.
    const int slave = open(slave_name, O_RDWR | O_NOCTTY);
    if (slave < 0) return fail("open the pseudo-terminal's slave side");
    (void)unlink(link.c_str());
    if (symlink(slave_name, link.c_str()) != 0) return fail("symlink");
    // The master side never gets termios of its own: libmodbus reads and writes the
    // descriptor it is given (modbus_set_socket), as it would a serial port.
    modbus_t* ctx = modbus_new_rtu("/dev/null", 115200, 'N', 8, 1);
    if (ctx == nullptr) return fail("modbus_new_rtu");
    modbus_set_slave(ctx, address);
    modbus_set_socket(ctx, master);
    modbus_mapping_t* map = modbus_mapping_new(0, 0, holding_count, 0);
    if (map == nullptr) return fail("modbus_mapping_new");
    for (int i = 0; i < holding_count; ++i) map->tab_registers[i] = static_cast<std::uint16_t>(i);
    std::printf("ready\n");
    std::fflush(stdout);
    std::uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];
    for (;;) {
        const int length = modbus_receive(ctx, query);
        if (length == 0) continue;  // a request for another slave
        if (length < 0) {
            if (errno == EIO || errno == EBADF) return fail("modbus_receive");
            continue;  // a bad CRC or a frame cut short: libmodbus flushed it
        }
        const int function = query[1];
        const int first = (query[2] << 8) | query[3];
        if (function == MODBUS_FC_READ_HOLDING_REGISTERS && first == misfit_address) {
            const std::uint8_t misfit[] = {static_cast<std::uint8_t>(address), MODBUS_FC_READ_HOLDING_REGISTERS,
                                           0x02, 0x12, 0x34};
            (void)modbus_send_raw_request(ctx, misfit, sizeof misfit);
            continue;
        }
        (void)modbus_reply(ctx, query, length, map);
    }
}
