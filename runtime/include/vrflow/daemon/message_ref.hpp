#pragma once

#include "vrflow/ipc/block_ref.hpp"

namespace vrflow::daemon {

/// The daemon's hold on a message block: the host's one block handle type (ipc::BlockRef).
using MessageRef = ipc::BlockRef;

}  // namespace vrflow::daemon
