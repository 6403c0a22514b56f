"""The detector's input gain (model.json's "brighten": {"target_mean", "max_gain"}), shared by
training (train.py), the benchmarks (benchmarks/perception_bench.py) and, in C++, the detector
engine (engines/detector/detector.cpp, brighten_image): a dark image is made brighter as a
camera's auto exposure would, before the network sees it."""
import cv2


def brighten(image, target_mean, max_gain):
    """Every value times clamp(target_mean / the image's mean value, 1, max_gain), saturated
    (cv2.convertScaleAbs, as the detector engine does it); the image itself when the gain is 1."""
    mean = sum(cv2.mean(image)[:3]) / 3.0
    gain = min(max(target_mean / max(mean, 1e-6), 1.0), max_gain)
    return image if gain <= 1.0 else cv2.convertScaleAbs(image, alpha=gain)


def from_meta(meta):
    """(target_mean, max_gain) from a model.json dict, or None (no gain: YOLO models, models
    before session 25)."""
    b = meta.get("brighten")
    return (float(b["target_mean"]), float(b["max_gain"])) if b else None
