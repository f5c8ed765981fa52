"""Where a controller manager's services are, as ros_control's tools name them."""

SERVICES = ('load_controller', 'unload_controller', 'switch_controller', 'list_controllers',
            'list_controller_types', 'reload_controller_libraries')


def service_name(namespace, service):
    """`<namespace>/controller_manager/<service>`; with no namespace the name stays relative, so
    it resolves in the caller's namespace (a spawner started with ns="/one_DOF_robot" finds
    /one_DOF_robot/controller_manager/...), as ros_control's spawner does."""
    if namespace and not namespace.endswith('/'):
        namespace += '/'
    return (namespace or '') + 'controller_manager/' + service
