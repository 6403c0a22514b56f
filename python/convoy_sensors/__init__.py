"""Helpers for Convoy's sensor datapacks (issue 27): point_cloud reads a LiDAR's
PointCloudDataPack as numpy."""
