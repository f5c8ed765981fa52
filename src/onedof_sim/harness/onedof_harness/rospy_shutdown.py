"""rospy's shutdown for a process that goes on after it.

rospy.signal_shutdown closes its XML-RPC server's socket under the thread still serving it
(rosgraph.xmlrpc.XmlRpcNode): that thread's poll then finds the closed socket ready at once, its
accept fails, and it polls again, a core's worth of CPU until the process exits. A process that
has more to do after its node is done (the tutorial player's in-sim run and figures, the
benchmark's table) ends that thread too."""


def shut_down_rospy(rospy, reason):
    """rospy.signal_shutdown(reason), then the end of the XML-RPC server's thread."""
    import rosgraph.xmlrpc
    # The node's shutdown hook is the only reference rospy keeps to its XML-RPC server.
    servers = [hook.__self__.server for hook in list(rospy.core._shutdown_hooks)
               if isinstance(getattr(hook, '__self__', None), rosgraph.xmlrpc.XmlRpcNode)
               and hook.__self__.server is not None]
    rospy.signal_shutdown(reason)
    for server in servers:
        # serve_forever returns at its next poll (at once: the closed socket is ready), and
        # rospy's thread, shut down, does not serve again.
        server.shutdown()
