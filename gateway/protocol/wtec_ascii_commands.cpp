// implementation follows
#include "protocol/wtec_ascii_commands.hpp"
