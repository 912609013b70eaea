"""Act with an exported GQN policy: NumPy plus ONNX Runtime or PyTorch, no SB3, no sb3_gqn, no env.

    python examples/run_exported_policy.py policy.onnx policy.pt [observation.npy]

Without an observation file it acts on a zero observation of the shape the ONNX file declares. An observation file
of another dtype (NumPy saves float64 by default) is cast to the dtype the file declares.
"""

import sys

import numpy as np
import onnxruntime
import torch

USAGE = "usage: python examples/run_exported_policy.py policy.onnx policy.pt [observation.npy]"
#: ONNX Runtime's input type names -> NumPy dtypes
ONNX_DTYPES = {"tensor(float)": np.float32, "tensor(double)": np.float64, "tensor(uint8)": np.uint8}
ONNX_DTYPES.update({"tensor(int64)": np.int64, "tensor(int32)": np.int32, "tensor(bool)": np.bool_})

if len(sys.argv) not in (3, 4):
    sys.exit(f"{USAGE}\nerror: expected 2 or 3 arguments, got {len(sys.argv) - 1}")
onnx_path, torchscript_path, *observation_file = sys.argv[1:]
session = onnxruntime.InferenceSession(onnx_path, providers=["CPUExecutionProvider"])
inputs = session.get_inputs()
if len(inputs) != 1:
    sys.exit(
        f"{USAGE}\nerror: {onnx_path} takes a Dict observation ({[i.name for i in inputs]}); this example takes one array"
    )
dtype = ONNX_DTYPES.get(inputs[0].type, np.float32)
shape = tuple(inputs[0].shape[1:])
if observation_file:
    observation = np.load(observation_file[0])  # one observation, as the env returns it
    if observation.shape != shape:
        sys.exit(f"{USAGE}\nerror: {observation_file[0]} holds shape {observation.shape}, {onnx_path} takes {shape}")
    observation = observation.astype(dtype)  # e.g. float64 -> float32: ONNX Runtime refuses another dtype
else:
    observation = np.zeros(shape, dtype=dtype)
batch = observation[None]  # a batch of one
print("onnx:", *session.run(["action"], {inputs[0].name: batch})[0][0])
policy = torch.jit.load(torchscript_path)
print("torchscript:", *policy(torch.as_tensor(batch))[0].numpy())
