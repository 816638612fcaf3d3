// implementation follows
#include "protocol/crc16.hpp"
