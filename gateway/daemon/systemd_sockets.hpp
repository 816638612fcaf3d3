#pragma once
/// @file systemd_sockets.hpp
/// Socket activation, the systemd part: the sockets passed through LISTEN_FDS /
/// LISTEN_FDNAMES (sd_listen_fds_with_names(3)), described for match_passed_sockets().
#include <vector>

#include "daemon/passed_sockets.hpp"

namespace fieldbridge::daemon {

/// The sockets passed to this process, in descriptor order (from fd 3); empty when
/// LISTEN_FDS is unset or meant for another process. Takes the variables out of the
/// environment. Throws SocketActivationError when they are malformed.
[[nodiscard]] std::vector<PassedSocket> take_systemd_sockets();

}  // namespace fieldbridge::daemon
