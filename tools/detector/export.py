"""ONNX export of the detector for OpenCV 4.6 DNN: opset 12, batch 1 at a fixed input size,
BatchNorm folded, and the graph cleaned of what OpenCV 4.6 cannot read (Identity nodes on
constants)."""
import onnx
import torch


def clean(model_proto):
    g = model_proto.graph
    rename = {}
    keep = []
    for node in g.node:
        if node.op_type == "Identity":
            rename[node.output[0]] = node.input[0]
        else:
            keep.append(node)
    for node in keep:
        for i, name in enumerate(node.input):
            while name in rename:
                name = rename[name]
            node.input[i] = name
    for out in g.output:
        while out.name in rename:
            raise RuntimeError("an Identity feeds the output")
    del g.node[:]
    g.node.extend(keep)
    return model_proto


def export(model, path, input_size):
    """input_size: (width, height)."""
    model = model.eval()
    x = torch.zeros(1, 3, input_size[1], input_size[0])
    torch.onnx.export(model, x, path, opset_version=12, input_names=["images"],
                      output_names=["output0"], do_constant_folding=True)
    m = clean(onnx.load(path))
    onnx.checker.check_model(m)
    onnx.save(m, path)
    return sorted({n.op_type for n in m.graph.node})
