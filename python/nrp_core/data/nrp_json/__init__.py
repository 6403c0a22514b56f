"""JSON datapacks, as in NRP-Core's nrp_core.data.nrp_json."""

from nrp_core._datapacks import DataPackIdentifier, JsonDataPack, JsonRawData  # noqa: F401


class NlohmannJson(dict):
    """NRP-Core's JSON value type. In Convoy a graph's MQTT node of this type hands the parsed
    JSON (a dict, list...) to its functional node; the class itself is what `type=` names."""


__all__ = ["JsonDataPack", "JsonRawData", "DataPackIdentifier", "NlohmannJson"]
