// The process of a ROS node, when it runs on this machine: asked of the master (lookupNode) and
// of the node's own slave API (getPid), as rosnode does.
#pragma once

#include <optional>
#include <string>

namespace onedof_sim {

// The pid of `node` if its XML-RPC server listens on an address of this machine; empty if the
// node is elsewhere, unknown to the master, or did not answer. *silent_here (if given) says
// whether the master named an address of this machine where the node did not answer: a node
// killed does not unregister, and the master names it until another of that name registers.
std::optional<int> localNodePid(const std::string& node, bool* silent_here = nullptr);

}  // namespace onedof_sim
