"""Convoy's detector: a small single-stage, anchor-free network (three levels, strides 8, 16
and 32; an FPN neck; one shared-shape head per level) whose ONNX form OpenCV 4.6 DNN loads.

The neck's fusions and the heads' convolutions are dense 3x3 ones (neck="dense", the shipped
model's) or depthwise separable (neck="separable": a 3x3 depthwise convolution, then a 1x1
one): the same receptive field at about half the inference time in OpenCV (26-31 against
48-56 ms a 448x288 frame on one core), but a model trained so in session 25 found fewer
pedestrians (docs/perception.md, "Session 25").

Output, YOLOv8 layout: 1 x (4 + C) x N, N = the cells of the three levels; per cell cx, cy, w,
h in input pixels and C class scores (sigmoid). Boxes are decoded inside the network from
distances to the cell centre, l, t, r, b = sigmoid(x) * 16 * stride, with constant grids of
the output's full shape (OpenCV 4.6 cannot broadcast a constant in an Add or Mul). Only ops
OpenCV 4.6 reads: Conv (BatchNorm folded on export), LeakyRelu, Sigmoid, nearest Resize
(Upsample), Concat, Add, Mul, Sub, Reshape, Slice.
"""
import torch
import torch.nn as nn
import torch.nn.functional as F

STRIDES = (8, 16, 32)
RANGE = 16.0  # a box side reaches at most 2 x RANGE cells of its level


def conv(cin, cout, k=3, s=1):
    return nn.Sequential(nn.Conv2d(cin, cout, k, s, k // 2, bias=False), nn.BatchNorm2d(cout),
                         nn.LeakyReLU(0.1, inplace=True))


def separable(cin, cout):
    """A 3x3 depthwise convolution, then a 1x1 one (each with BatchNorm and LeakyReLU)."""
    return nn.Sequential(nn.Conv2d(cin, cin, 3, 1, 1, groups=cin, bias=False), nn.BatchNorm2d(cin),
                         nn.LeakyReLU(0.1, inplace=True), conv(cin, cout, 1))


NECKS = {"separable": separable, "dense": lambda cin, cout: conv(cin, cout, 3)}


class Residual(nn.Module):
    def __init__(self, c):
        super().__init__()
        self.a = conv(c, c // 2, 1)
        self.b = conv(c // 2, c, 3)

    def forward(self, x):
        return x + self.b(self.a(x))


class Detector(nn.Module):
    def __init__(self, num_classes, width=(16, 32, 64, 96, 128), input_size=320, neck="dense"):
        """input_size: a side (square) or (width, height), multiples of 32; neck: a key of NECKS
        (the fusions' and heads' 3x3 convolutions)."""
        super().__init__()
        if neck not in NECKS:
            raise ValueError("neck: '%s' is not one of %s" % (neck, ", ".join(sorted(NECKS))))
        fuse = NECKS[neck]
        w = width
        self.num_classes = num_classes
        self.input_size = tuple(input_size) if isinstance(input_size, (tuple, list)) else (input_size, input_size)
        self.stem = nn.Sequential(conv(3, w[0], 3, 2), conv(w[0], w[1], 3, 2), Residual(w[1]))
        self.s3 = nn.Sequential(conv(w[1], w[2], 3, 2), Residual(w[2]), Residual(w[2]))  # /8
        self.s4 = nn.Sequential(conv(w[2], w[3], 3, 2), Residual(w[3]), Residual(w[3]))  # /16
        self.s5 = nn.Sequential(conv(w[3], w[4], 3, 2), Residual(w[4]))  # /32
        self.lat5 = conv(w[4], w[3], 1)
        self.fuse4 = fuse(w[3] * 2, w[3])
        self.lat4 = conv(w[3], w[2], 1)
        self.fuse3 = fuse(w[2] * 2, w[2])
        self.down3 = conv(w[2], w[2], 3, 2)
        self.fuse4b = fuse(w[2] + w[3], w[3])
        self.down4 = conv(w[3], w[3], 3, 2)
        self.fuse5b = fuse(w[3] + w[4], w[4])
        self.heads = nn.ModuleList()
        for c in (w[2], w[3], w[4]):
            self.heads.append(nn.Sequential(fuse(c, c), nn.Conv2d(c, 4 + num_classes, 1)))
        prior = -4.6  # class scores start near 0.01
        for h in self.heads:
            nn.init.constant_(h[-1].bias[4:], prior)
            nn.init.constant_(h[-1].bias[:4], -1.0)
        self._grids = {}

    def features(self, x):
        x = self.stem(x)
        p3 = self.s3(x)
        p4 = self.s4(p3)
        p5 = self.s5(p4)
        nw, nh = self.input_size
        t5 = self.lat5(p5)  # (fixed sizes: the exported Resize gets constant sizes)
        f4 = self.fuse4(torch.cat([F.interpolate(t5, size=(nh // 16, nw // 16), mode="nearest"), p4], 1))
        t4 = self.lat4(f4)
        f3 = self.fuse3(torch.cat([F.interpolate(t4, size=(nh // 8, nw // 8), mode="nearest"), p3], 1))
        g4 = self.fuse4b(torch.cat([self.down3(f3), f4], 1))
        g5 = self.fuse5b(torch.cat([self.down4(g4), p5], 1))
        return [f3, g4, g5]

    def raw(self, x):
        """Per level: B x (4 + C) x H x W raw outputs."""
        return [h(f) for h, f in zip(self.heads, self.features(x))]

    def grids(self, size, device):
        """Constant tensors for decoding at input `size` (width, height): centres (1 x 2 x N)
        and scales (1 x 4 x N), each cell's stride x RANGE."""
        key = (size, str(device))
        if key not in self._grids:
            centres, scales = [], []
            for s in STRIDES:
                nx, ny = size[0] // s, size[1] // s
                ys, xs = torch.meshgrid(torch.arange(ny), torch.arange(nx), indexing="ij")
                c = torch.stack([xs.flatten(), ys.flatten()]).float().add(0.5).mul(s)
                centres.append(c)
                scales.append(torch.full((4, nx * ny), s * RANGE))
            self._grids[key] = (torch.cat(centres, 1)[None].to(device), torch.cat(scales, 1)[None].to(device))
        return self._grids[key]

    def decode(self, raws):
        """B x (4 + C) x N: cx, cy, w, h (input pixels) and class scores (probabilities)."""
        flat = torch.cat([r.flatten(2) for r in raws], 2)
        centres, scales = self.grids(self.input_size, flat.device)
        if flat.shape[0] != 1:  # (exported with batch 1: no Expand in the graph)
            centres = centres.expand(flat.shape[0], -1, -1)
            scales = scales.expand(flat.shape[0], -1, -1)
        ltrb = torch.sigmoid(flat[:, :4]) * scales
        lt, rb = ltrb[:, :2], ltrb[:, 2:]
        cxy = centres + (rb - lt) * 0.5
        wh = lt + rb
        return torch.cat([cxy, wh, torch.sigmoid(flat[:, 4:])], 1)

    def forward(self, x):
        return self.decode(self.raw(x))
