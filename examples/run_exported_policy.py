"""Act with an exported GQN policy: NumPy plus ONNX Runtime or PyTorch, no SB3, no sb3_gqn, no env."""

import numpy as np
import onnxruntime
import torch

observation = np.load("observation.npy")  # one observation, as the env returns it
session = onnxruntime.InferenceSession("policy.onnx", providers=["CPUExecutionProvider"])
print("onnx:", *session.run(["action"], {"observation": observation[None]})[0][0])  # a batch of one
policy = torch.jit.load("policy.pt")
print("torchscript:", *policy(torch.as_tensor(observation[None]))[0].numpy())
