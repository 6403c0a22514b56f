"""Reinforcement learning on Convoy: gymnasium-style environments over NRP-Core's Python
client (nrp_client). See docs/gym.md.

    from convoy_gym import DrivingEnv
    env = DrivingEnv()                      # experiments/rl_parkring
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step([0.0, 6.0])
    env.close()

    from convoy_gym import VectorDrivingEnv
    envs = VectorDrivingEnv(2)              # 2 servers, stepped together
    obs, infos = envs.reset(seed=0)         # obs: (2, 16); env i gets seed 0 + i

    from convoy_gym import ScenarioDrivingEnv, MultiAgentDrivingEnv
    env = ScenarioDrivingEnv("benchmarks/suite/cut_in.xosc")          # one .xosc run an episode
    menv = MultiAgentDrivingEnv("benchmarks/suite/cut_in.xosc", agents=["Ego", "Cutter"])

Pure Python with numpy; uses gymnasium.spaces when gymnasium is installed. The scenario
environments are imported on first use (they need python/convoy_scenario and convoy_bench).
"""
from convoy_gym import spaces
from convoy_gym.driving_env import DrivingEnv, default_reward
from convoy_gym.vector_env import VectorDrivingEnv

__all__ = ["DrivingEnv", "VectorDrivingEnv", "ScenarioDrivingEnv", "MultiAgentDrivingEnv",
           "default_reward", "spaces"]


def __getattr__(name):
    if name == "ScenarioDrivingEnv":
        from convoy_gym.scenario_env import ScenarioDrivingEnv
        return ScenarioDrivingEnv
    if name == "MultiAgentDrivingEnv":
        from convoy_gym.multi_agent_env import MultiAgentDrivingEnv
        return MultiAgentDrivingEnv
    raise AttributeError("module 'convoy_gym' has no attribute %r" % name)
