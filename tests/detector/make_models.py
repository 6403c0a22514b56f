"""Builds tiny ONNX "YOLO" models for detector_test: whatever the input image, their output
is a fixed tensor in YOLOv5 layout [1, N, 5+C] or YOLOv8 layout [1, 4+C, N], holding known
boxes (see detector_test.cpp for the expected detections).

Usage: /usr/bin/python3 make_models.py OUTDIR
Writes OUTDIR/yolov5_test.onnx, OUTDIR/yolov8_test.onnx and OUTDIR/classes3.txt.
"""
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

SIZE = 640


def fixed_output_model(values, path):
    """images [1,3,640,640] -> Slice to the output's size -> *0 -> + constant -> reshape."""
    values = np.asarray(values, dtype=np.float32)
    _, rows, cols = values.shape
    inits = [
        numpy_helper.from_array(np.array([0, 0, 0, 0], np.int64), "starts"),
        numpy_helper.from_array(np.array([1, 1, rows, cols], np.int64), "ends"),
        numpy_helper.from_array(np.array([0], np.float32).reshape(()), "zero"),
        numpy_helper.from_array(values.reshape(1, 1, rows, cols), "table"),
        numpy_helper.from_array(np.array([1, rows, cols], np.int64), "out_shape"),
    ]
    nodes = [
        helper.make_node("Slice", ["images", "starts", "ends"], ["sliced"]),
        helper.make_node("Mul", ["sliced", "zero"], ["zeroed"]),
        helper.make_node("Add", ["zeroed", "table"], ["summed"]),
        helper.make_node("Reshape", ["summed", "out_shape"], ["output0"]),
    ]
    graph = helper.make_graph(
        nodes, "fixed_yolo",
        [helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, SIZE, SIZE])],
        [helper.make_tensor_value_info("output0", TensorProto.FLOAT, [1, rows, cols])],
        inits)
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, path)


def yolov5():
    # 3 classes (car, person, dog), 20 rows of cx, cy, w, h, obj, cls0..2 (network pixels).
    t = np.zeros((1, 20, 8), np.float32)
    t[0, 0] = [100, 200, 50, 40, 0.9, 0.8, 0.1, 0.1]   # car 0.72 -> kept
    t[0, 1] = [104, 202, 50, 40, 0.8, 0.8, 0.1, 0.1]   # car 0.64, overlaps row 0 -> NMS
    t[0, 2] = [100, 200, 50, 40, 0.9, 0.1, 0.7, 0.1]   # person 0.63, same box -> kept
    t[0, 3] = [300, 300, 20, 20, 0.5, 0.1, 0.1, 0.4]   # dog 0.2 < 0.25 -> dropped
    t[0, 4] = [600, 540, 100, 60, 1.0, 0.0, 0.0, 0.95]  # dog 0.95, clipped to the image
    return t


def yolov8():
    # 80 COCO classes, 100 anchors: [1, 84, 100].
    t = np.zeros((1, 84, 100), np.float32)

    def put(col, cx, cy, w, h, cls, score):
        t[0, 0:4, col] = [cx, cy, w, h]
        t[0, 4 + cls, col] = score
    put(0, 320, 320, 200, 100, 0, 0.9)    # person 0.9 -> kept
    put(1, 325, 322, 200, 100, 0, 0.85)   # person 0.85, overlaps col 0 -> NMS
    put(2, 100, 100, 40, 40, 2, 0.5)      # car 0.5 -> kept
    put(3, 500, 300, 30, 30, 5, 0.2)      # bus 0.2 < 0.25 -> dropped
    return t


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    fixed_output_model(yolov5(), os.path.join(out, "yolov5_test.onnx"))
    fixed_output_model(yolov8(), os.path.join(out, "yolov8_test.onnx"))
    with open(os.path.join(out, "classes3.txt"), "w") as f:
        f.write("car\nperson\ndog\n")


if __name__ == "__main__":
    main()
