// implementation follows
#include "protocol/decode_result.hpp"
