"""NRP-Core 1.4's ROS message modules, on rospy: `nrp_core.data.nrp_ros.<package>` is the
rospy message module `<package>.msg` (std_msgs, geometry_msgs, sensor_msgs, and any other
package rospy can import), so that

    from nrp_core.data.nrp_ros.std_msgs import String
    from nrp_core.data.nrp_ros.sensor_msgs_conversions import Image_to_ros

work as in NRP-Core. NRP-Core's classes are boost.python wrappers of the roscpp messages, with
the same field names; here they are the rospy classes themselves, so the
`<package>_conversions` functions (`<Message>_to_ros`, `<Message>_from_ros`) return their
argument.
"""
import importlib
import importlib.abc
import importlib.util
import sys
import types

_PREFIX = __name__ + "."


def _identity(msg):
    return msg


class _ConversionsModule(types.ModuleType):
    def __getattr__(self, name):
        if name.endswith("_to_ros") or name.endswith("_from_ros"):
            return _identity
        raise AttributeError("module %r has no attribute %r" % (self.__name__, name))


class _Finder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, fullname, path=None, target=None):
        if not fullname.startswith(_PREFIX) or "." in fullname[len(_PREFIX):]:
            return None
        package = fullname[len(_PREFIX):]
        if not package.endswith("_conversions") and \
                importlib.util.find_spec(package) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        package = spec.name[len(_PREFIX):]
        if package.endswith("_conversions"):
            return _ConversionsModule(spec.name)
        return None

    def exec_module(self, module):
        package = module.__name__[len(_PREFIX):]
        if isinstance(module, _ConversionsModule):
            return
        try:
            msg = importlib.import_module(package + ".msg")
        except ImportError as e:
            raise ImportError("%s: the ROS message package %s cannot be imported with rospy (%s)"
                              % (module.__name__, package, e)) from None
        for name in dir(msg):
            value = getattr(msg, name)
            if isinstance(value, type) and hasattr(value, "_type"):
                setattr(module, name, value)
        module.__all__ = [n for n in dir(module) if not n.startswith("_")]


if not any(isinstance(f, _Finder) for f in sys.meta_path):
    sys.meta_path.append(_Finder())
