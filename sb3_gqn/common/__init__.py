"""What GQN, DecQN, the export and the experiments share: nested bins and their masks, the decoupled TD targets, the
torsos, the replay buffers (n-step, prioritized, ``Dict``), the Gymnasium wrappers, env ids, argument checks and
evaluation (greedy rollouts, smoothness figures, the learning-curve callback)."""
