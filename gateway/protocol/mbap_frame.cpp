// implementation follows
#include "protocol/mbap_frame.hpp"
