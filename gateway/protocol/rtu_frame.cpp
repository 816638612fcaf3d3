// implementation follows
#include "protocol/rtu_frame.hpp"
