"""Reinforcement learning on Convoy: gymnasium-style environments over NRP-Core's Python
client (nrp_client). See docs/gym.md.

    from convoy_gym import DrivingEnv
    env = DrivingEnv()                      # experiments/rl_parkring
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step([0.0, 6.0])
    env.close()

Pure Python with numpy; uses gymnasium.spaces when gymnasium is installed.
"""
from convoy_gym import spaces
from convoy_gym.driving_env import DrivingEnv, default_reward

__all__ = ["DrivingEnv", "default_reward", "spaces"]
