// implementation follows
#include "protocol/modbus_pdu.hpp"
