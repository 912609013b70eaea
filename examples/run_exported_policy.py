"""Act with an exported GQN policy: NumPy plus ONNX Runtime or PyTorch, no SB3, no sb3_gqn, no env.

    python examples/run_exported_policy.py policy.onnx policy.pt [observation.npy]

Without an observation file it acts on a zero observation of the shape the ONNX file declares.
"""

import sys

import numpy as np
import onnxruntime
import torch

onnx_path, torchscript_path, *observation_file = sys.argv[1:]
session = onnxruntime.InferenceSession(onnx_path, providers=["CPUExecutionProvider"])
if observation_file:
    observation = np.load(observation_file[0])  # one observation, as the env returns it
else:
    observation = np.zeros(session.get_inputs()[0].shape[1:], dtype=np.float32)
batch = observation[None]  # a batch of one
print("onnx:", *session.run(["action"], {"observation": batch})[0][0])
policy = torch.jit.load(torchscript_path)
print("torchscript:", *policy(torch.as_tensor(batch))[0].numpy())
