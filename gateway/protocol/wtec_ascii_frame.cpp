// implementation follows
#include "protocol/wtec_ascii_frame.hpp"
