#!/usr/bin/env python3
"""Writes the small ONNX networks of tests/denoiser, with weights a reader can check by hand.

Run from anywhere: /usr/bin/python3 tests/denoiser/data/make_test_networks.py
Needs only python3-onnx (no torch), so the committed files can be regenerated anywhere; CI does
not run this script, it uses the committed .onnx files.

  two_conv.onnx       input 1x1xHxW -> Conv 3x3 (1 -> 2 channels, zero padding 1) -> Relu
                      -> Conv 3x3 (2 -> 1 channel, zero padding 1) -> output 1x1xHxW.
                      Receptive field: 2 pixels each way. tests/denoiser/denoiser_test.cc
                      computes the same network in double precision from the weights below.
  two_scale.onnx      input 1x1xHxW (H, W even) -> Conv 3x3 stride 2 (1 -> 2 channels, zero
                      padding 1; the weights of two_conv's first layer) -> Relu ->
                      ConvTranspose 2x2 stride 2 (2 -> 1 channel) -> Add input -> output: a
                      network with a half-resolution middle and a skip connection, as the
                      shipped one has. Receptive field: 2 pixels each way; input multiple 2.
  two_channels.onnx   a single Conv 3x3 with 2 output channels: the wrong output shape.
  three_inputs.onnx   a single Conv 3x3 reading 3 input channels: the wrong input shape.
"""
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

# Multiples of 1/8: exact in float32, so the C++ test's double computation sees the same values.
FIRST_WEIGHTS = np.array(
    [[[[0, 1, 0], [1, -4, 1], [0, 1, 0]]],  # a Laplacian
     [[[1, 2, 1], [0, 0, 0], [-1, -2, -1]]]],  # a vertical Sobel
    dtype=np.float32) / 8
FIRST_BIAS = np.array([0.125, -0.25], dtype=np.float32)
SECOND_WEIGHTS = np.array(
    [[[[0, 0, 0], [0, 4, 0], [0, 0, 0]],
      [[1, 0, -1], [2, 0, -2], [1, 0, -1]]]],  # channel 0 at the centre; a Sobel of channel 1
    dtype=np.float32) / 8
SECOND_BIAS = np.array([-0.0625], dtype=np.float32)
# ConvTranspose weights (input channel, output channel, row, column): output pixel (2i + a, 2j + b)
# is UP_BIAS + sum over channels c of UP_WEIGHTS[c, 0, a, b] * half-resolution pixel (i, j).
UP_WEIGHTS = np.array(
    [[[[1, 2], [3, 4]]],
     [[[-2, 1], [0, -1]]]],
    dtype=np.float32) / 8
UP_BIAS = np.array([0.25], dtype=np.float32)


def conv(name, input_name, output_name, weights, bias):
    initializers = [numpy_helper.from_array(weights, name + "_w"),
                    numpy_helper.from_array(bias, name + "_b")]
    node = helper.make_node("Conv", [input_name, name + "_w", name + "_b"], [output_name],
                            kernel_shape=[3, 3], pads=[1, 1, 1, 1], name=name)
    return node, initializers


def save(path, nodes, initializers, input_channels, output_channels):
    graph = helper.make_graph(
        nodes, "evfs_test_network",
        [helper.make_tensor_value_info("input", TensorProto.FLOAT, [1, input_channels, "H", "W"])],
        [helper.make_tensor_value_info("output", TensorProto.FLOAT,
                                       [1, output_channels, "H", "W"])],
        initializers)
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)],
                              producer_name="evfs tests/denoiser/data/make_test_networks.py")
    model.ir_version = 6
    onnx.checker.check_model(model)
    onnx.save(model, path)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    first, first_init = conv("conv1", "input", "hidden", FIRST_WEIGHTS, FIRST_BIAS)
    relu = helper.make_node("Relu", ["hidden"], ["hidden_relu"], name="relu1")
    second, second_init = conv("conv2", "hidden_relu", "output", SECOND_WEIGHTS, SECOND_BIAS)
    save(os.path.join(here, "two_conv.onnx"), [first, relu, second], first_init + second_init, 1, 1)

    down, down_init = conv("down", "input", "coarse", FIRST_WEIGHTS, FIRST_BIAS)
    down.attribute.append(helper.make_attribute("strides", [2, 2]))
    coarse_relu = helper.make_node("Relu", ["coarse"], ["coarse_relu"], name="relu_coarse")
    up_init = [numpy_helper.from_array(UP_WEIGHTS, "up_w"), numpy_helper.from_array(UP_BIAS, "up_b")]
    up = helper.make_node("ConvTranspose", ["coarse_relu", "up_w", "up_b"], ["fine"],
                          kernel_shape=[2, 2], strides=[2, 2], name="up")
    skip = helper.make_node("Add", ["fine", "input"], ["output"], name="skip")
    save(os.path.join(here, "two_scale.onnx"), [down, coarse_relu, up, skip],
         down_init + up_init, 1, 1)

    wide, wide_init = conv("conv1", "input", "output", FIRST_WEIGHTS, FIRST_BIAS)
    save(os.path.join(here, "two_channels.onnx"), [wide], wide_init, 1, 2)

    rgb_weights = np.repeat(SECOND_WEIGHTS[:, :1], 3, axis=1)
    rgb, rgb_init = conv("conv1", "input", "output", rgb_weights, SECOND_BIAS)
    save(os.path.join(here, "three_inputs.onnx"), [rgb], rgb_init, 3, 1)


if __name__ == "__main__":
    main()
