"""VectorDrivingEnv: several DrivingEnvs stepped together, in gymnasium's vector-env shape.

    from convoy_gym import VectorDrivingEnv

    with VectorDrivingEnv(2, max_steps=400) as envs:
        obs, infos = envs.reset(seed=1)              # env i: seed 1 + i; obs: (2, 16)
        for _ in range(400):
            steer = np.clip(0.8 * obs[:, 4], -0.55, 0.55)
            actions = np.stack([steer, np.full(2, 6.0)], axis=1)   # (2, 2)
            obs, rewards, terminations, truncations, infos = envs.step(actions)

    VectorDrivingEnv(2, camera=(84, 84))   # obs: {"state": (2, 16), "camera": (2, 84, 84, 3)}

Each sub-environment is a DrivingEnv, i.e. its own NRPCoreSim server process (and its
engines' processes) on its own port: the simulations already run in parallel processes. This
class only drives them at the same time, from one thread: a step sends every environment its
action (DrivingEnv.step_begin, over each server's local socket) before it waits for any reply
(step_finish), so the servers step together while this process waits; resets run on a thread
per environment. Their servers and engines wait without spinning (DrivingEnv's spin=False),
since the environments share the cores (see docs/gym.md, "Parallel environments", for the
measured speed-up). With 2 or more environments, each one's server and engines run on a core
of their own (cpu_affinity="auto", affinity.py): environment i's on core i (round-robin over
the cores this process may use), so that two environments' pipelined processes do not take
each other's cores. With a camera, an environment pinned to one core renders with 2
llvmpipe threads (LP_NUM_THREADS=2 unless set; Mesa would use none there: measured slower).

Camera: with camera=(H, W) (DrivingEnv's), observations are batched as gymnasium batches a
Dict space: {"state": (num_envs, 16) float32, "camera": (num_envs, H, W, 3) uint8};
observation_space is that batched Dict, single_observation_space the DrivingEnv's Dict.

Autoreset: gymnasium's default for AsyncVectorEnv (gymnasium >= 1.0, AutoresetMode.NEXT_STEP).
When a sub-environment's episode ends at step t, step t returns its last observation with
terminated / truncated set; the next step() resets that sub-environment (its action is
ignored) and returns the new episode's first observation with reward 0.0,
terminated = truncated = False. The reset draws no new seed: it continues the
sub-environment's generator, as DrivingEnv.reset() does.
autoreset_mode="same_step" gives gymnasium 0.29's behaviour instead (the reset happens in the
same step; the last observation and info are in infos["final_obs"] / infos["final_info"]),
and "disabled" leaves the resetting to the caller (reset(options={"reset_mask": mask})).

infos: gymnasium's vector layout, a dict whose values are arrays of length num_envs, each key
`k` with a boolean mask `_k` saying which sub-environments gave it (nested dicts likewise).

Errors: an action outside the action space raises ValueError naming the sub-environment and
the element (`env 1: action[0] (steer) = 0.9 is above ...`) before any environment steps, so
nothing changes and the vector env stays usable. Any other error in a sub-environment (its
server died, an observation is missing, ...) closes every sub-environment and is raised with
the sub-environment's index: no NRPCoreSim is left behind.
"""
import concurrent.futures
import threading

import numpy as np

from convoy_gym import spaces
from convoy_gym.affinity import core_sets, pinned, render_threads
from convoy_gym.closing import ClosesOnExit
from convoy_gym.driving_env import DrivingEnv
from convoy_gym.world_variant import check_camera

__all__ = ["VectorDrivingEnv", "AUTORESET_MODES"]

AUTORESET_MODES = ("next_step", "same_step", "disabled")


class SubEnvError(RuntimeError):
    """An error inside sub-environment `index` (the vector env is closed)."""

    def __init__(self, index, error):
        super().__init__("env %d: %s: %s" % (index, type(error).__name__, error))
        self.index = index
        self.error = error


class VectorDrivingEnv(ClosesOnExit):
    """num_envs DrivingEnv(**env_kwargs), each its own NRPCoreSim, stepped concurrently.

    The gymnasium vector API: reset(seed=None, options=None) -> (obs [num_envs, 16], infos),
    step(actions [num_envs, 2]) -> (obs, rewards, terminations, truncations, infos), close(),
    num_envs, single_observation_space, single_action_space, observation_space and
    action_space (batched spaces), and a `with` block. With camera=(H, W), obs is a dict
    {"state": [num_envs, 16], "camera": [num_envs, H, W, 3] uint8}."""

    metadata = {"render_modes": [], "autoreset_mode": "next_step"}
    render_mode = None

    def __init__(self, num_envs, autoreset_mode="next_step", env_fns=None, cpu_affinity="auto",
                 **env_kwargs):
        """:param num_envs: number of sub-environments (processes), >= 1
        :param autoreset_mode: "next_step" (gymnasium's default), "same_step" or "disabled"
        :param env_fns: optional list of num_envs callables returning a DrivingEnv-like
            environment (instead of DrivingEnv(**env_kwargs))
        :param cpu_affinity: the cores of each environment's server and engines (they inherit
            them from the thread that starts the server; this process is not pinned):
            "auto" (default): one core each, round-robin over os.sched_getaffinity(0), when
            num_envs >= 2, none when 1; True: one core each, also for 1; None / False: not
            pinned; or a list of num_envs entries, each a core, a set of cores or None
        :param env_kwargs: DrivingEnv's arguments, the same for every sub-environment
            (address must not be given: each gets a free port); spin defaults to False here:
            the environments' processes share the cores, and a process spinning while it
            waits takes a core another environment could use"""
        self.envs = []
        self._pool = None
        num_envs = int(num_envs)
        if num_envs < 1:
            raise ValueError("VectorDrivingEnv: num_envs must be >= 1, got %r" % (num_envs,))
        if autoreset_mode not in AUTORESET_MODES:
            raise ValueError("VectorDrivingEnv: autoreset_mode must be one of %s, got %r"
                             % (", ".join(AUTORESET_MODES), autoreset_mode))
        if env_kwargs.get("address"):
            raise ValueError("VectorDrivingEnv: every sub-environment needs its own address; "
                             "do not pass address=")
        if env_kwargs.get("camera") is not None:
            try:
                env_kwargs["camera"] = check_camera(env_kwargs["camera"])
            except ValueError as e:
                raise ValueError("VectorDrivingEnv: %s" % e) from None
        if env_fns is not None and len(env_fns) != num_envs:
            raise ValueError("VectorDrivingEnv: %d env_fns for %d envs" % (len(env_fns), num_envs))
        try:
            self.cpu_sets = core_sets(cpu_affinity, num_envs)
        except ValueError as e:
            raise ValueError("VectorDrivingEnv: %s" % e) from None
        self.num_envs = num_envs
        self.autoreset_mode = autoreset_mode
        self.metadata = dict(self.metadata, autoreset_mode=autoreset_mode)
        self._lock = threading.Lock()
        self._pool = concurrent.futures.ThreadPoolExecutor(
            max_workers=num_envs, thread_name_prefix="VectorDrivingEnv")
        env_kwargs.setdefault("spin", False)  # the environments share the cores
        make = env_fns or [lambda: DrivingEnv(**env_kwargs)] * num_envs
        # start the servers at the same time; if one fails, close the others
        # (a camera pinned to one core: llvmpipe's threads as measured, affinity.py)
        errors = []
        with render_threads(env_kwargs.get("camera") is not None and any(
                cores is not None and len(cores) == 1 for cores in self.cpu_sets)):
            futures = [self._pool.submit(_started_on, fn, cores)
                       for fn, cores in zip(make, self.cpu_sets)]
            for i, f in enumerate(futures):
                try:
                    self.envs.append(f.result())
                except BaseException as e:  # noqa: BLE001 - re-raised below, after cleanup
                    errors.append((i, e))
        if errors:
            self.close()
            i, e = errors[0]
            raise SubEnvError(i, e) from e
        self.single_observation_space = self.envs[0].observation_space
        self.single_action_space = self.envs[0].action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._started = False

    # --- gymnasium's vector API ------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Resets every sub-environment (or those in options["reset_mask"]). seed: an int
        (env i gets seed + i), a list of num_envs ints / None, or None (each continues its
        generator). Returns (obs [num_envs, ...], infos)."""
        self._check_open()
        if seed is None or isinstance(seed, (int, np.integer)):
            seeds = [None if seed is None else int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError("reset(): %d seeds for %d envs" % (len(seeds), self.num_envs))
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        mask = np.ones(self.num_envs, bool) if mask is None else np.asarray(mask, dtype=bool)
        if mask.shape != (self.num_envs,):
            raise ValueError("reset(): reset_mask has shape %s, expected (%d,)"
                             % (mask.shape, self.num_envs))
        if not self._started and not mask.all():
            raise RuntimeError("VectorDrivingEnv: the first reset() must reset every env")
        jobs = {i: (lambda e=e, s=seeds[i]: e.reset(seed=s, options=options or None))
                for i, e in enumerate(self.envs) if mask[i]}
        results = self._run(jobs)
        if not self._started:
            self._obs = empty_batch(self.observation_space)
            self._started = True
        infos = {}
        for i, (obs, info) in results.items():
            set_row(self._obs, i, obs)
            self._autoreset[i] = False
            _add_info(infos, info, i, self.num_envs)
        return copy_batch(self._obs), infos

    def step(self, actions):
        """Steps every sub-environment with its row of `actions` ([num_envs, 2]); a
        sub-environment whose episode ended at the previous step is reset instead (see the
        module's docstring). Returns (obs, rewards, terminations, truncations, infos)."""
        self._check_open()
        if not self._started:
            raise RuntimeError("VectorDrivingEnv.step() before reset()")
        actions = self._check_actions(actions)
        n = self.num_envs
        if all(hasattr(env, "step_begin") for env in self.envs):
            results = self._step_together(actions)
        else:
            jobs = {}
            for i, env in enumerate(self.envs):
                if self._autoreset[i]:
                    jobs[i] = lambda e=env: ("reset",) + tuple(e.reset())
                else:
                    jobs[i] = self._step_job(env, actions[i])
            results = self._run(jobs)
        obs = self._obs
        rewards = np.zeros(n, dtype=np.float64)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        infos = {}
        for i in range(n):
            r = results[i]
            if r[0] == "reset":
                row, info = r[1], r[2]
            else:
                row, rewards[i], terminations[i], truncations[i], info = r[1:6]
                if len(r) > 6:  # same_step: reset in this step, the last one in final_*
                    _add_final(infos, row, info, i, n)
                    row, info = r[6], r[7]
            set_row(obs, i, row)
            _add_info(infos, info, i, n)
        if self.autoreset_mode == "next_step":
            self._autoreset = terminations | truncations
        return copy_batch(obs), rewards, terminations, truncations, infos

    def close(self):
        """Closes every sub-environment (their servers and engines). Safe to call twice."""
        envs, self.envs = getattr(self, "envs", []), []
        pool, self._pool = getattr(self, "_pool", None), None
        errors = []
        if envs:
            # shut the servers down together: each close() waits for its processes
            closer = concurrent.futures.ThreadPoolExecutor(max_workers=len(envs))
            for f in [closer.submit(e.close) for e in envs]:
                try:
                    f.result()
                except Exception as e:  # noqa: BLE001 - close the others first
                    errors.append(e)
            closer.shutdown(wait=True)
        if pool is not None:
            pool.shutdown(wait=True)
        if errors:
            raise errors[0]

    def call(self, name, *args, **kwargs):
        """Calls `name` (a method or an attribute) on every sub-environment; a tuple."""
        self._check_open()
        out = []
        for env in self.envs:
            attr = getattr(env, name)
            out.append(attr(*args, **kwargs) if callable(attr) else attr)
        return tuple(out)

    def get_attr(self, name):
        return tuple(getattr(env, name) for env in self.envs)

    def render(self):
        return None

    @property
    def closed(self):
        return not self.envs

    @property
    def unwrapped(self):
        return self

    def __len__(self):
        return self.num_envs

    def __repr__(self):
        return "VectorDrivingEnv(num_envs=%d, autoreset_mode=%r)" % (self.num_envs,
                                                                     self.autoreset_mode)

    # --- the rest --------------------------------------------------------------------------
    def _step_job(self, env, action):
        same_step = self.autoreset_mode == "same_step"

        def job():
            out = ("step",) + tuple(env.step(action))
            if same_step and (out[3] or out[4]):
                out += tuple(env.reset())
            return out
        return job

    def _step_together(self, actions):
        """step()'s results {index: ("step", ...) or ("reset", ...)}: the environments due an
        autoreset reset first (concurrently), then every other one is sent its action
        (step_begin) before any reply is awaited (step_finish), all from this thread: the
        servers step at the same time without a thread per environment."""
        resets = {i: (lambda e=env: ("reset",) + tuple(e.reset()))
                  for i, env in enumerate(self.envs) if self._autoreset[i]}
        results = self._run(resets) if resets else {}
        same_step = self.autoreset_mode == "same_step"
        begun, errors = [], []
        for i, env in enumerate(self.envs):
            if i in resets:
                continue
            try:
                env.step_begin(actions[i])
                begun.append(i)
            except BaseException as e:  # noqa: BLE001 - re-raised below, after cleanup
                errors.append((i, e))
                break
        for i in begun:
            try:
                out = ("step",) + tuple(self.envs[i].step_finish())
                if same_step and (out[3] or out[4]):
                    out += tuple(self.envs[i].reset())
                results[i] = out
            except BaseException as e:  # noqa: BLE001 - re-raised below, after cleanup
                errors.append((i, e))
        if errors:
            self._fail(sorted(errors, key=lambda x: x[0]))
        return results

    def _check_open(self):
        if not self.envs:
            raise RuntimeError("VectorDrivingEnv is closed; make a new one")

    def _check_actions(self, actions):
        try:
            a = np.asarray(actions, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError("actions %r are not a [%d, %d] array of numbers"
                             % (actions, self.num_envs, self.single_action_space.shape[0])) \
                from None
        if a.shape != (self.num_envs,) + tuple(self.single_action_space.shape):
            raise ValueError("actions have shape %s, expected %s (num_envs, action)"
                             % (a.shape, (self.num_envs,) + tuple(self.single_action_space.shape)))
        for i, env in enumerate(self.envs):
            if self._autoreset[i]:
                continue  # this env resets instead of stepping: its action is ignored
            check = getattr(env, "_check_action", None)
            if check is None:
                continue
            try:
                check(a[i])
            except ValueError as e:
                raise ValueError("env %d: %s" % (i, e)) from None
        return a

    def _run(self, jobs):
        """Runs {index: callable} concurrently; returns {index: result}. If any fails, closes
        everything and raises the first failure (lowest index) as SubEnvError."""
        with self._lock:
            futures = {i: self._pool.submit(job) for i, job in jobs.items()}
            results, errors = {}, []
            for i, f in futures.items():
                try:
                    results[i] = f.result()
                except BaseException as e:  # noqa: BLE001 - re-raised below, after cleanup
                    errors.append((i, e))
        if errors:
            self._fail(errors)
        return results

    def _fail(self, errors):
        """Closes everything and raises the first of [(index, error)] as SubEnvError."""
        try:
            self.close()
        finally:
            i, e = errors[0]
            if isinstance(e, KeyboardInterrupt):
                raise e
            raise SubEnvError(i, e) from e


def _started_on(make, cores):
    """make() on this thread, with the processes it starts pinned to `cores` (None: not)."""
    with pinned(cores):
        return make()


def batch_space(space, n):
    """gymnasium's batch_space for a Box or a Dict of Boxes: n rows of `space`."""
    if isinstance(space, spaces.Dict):
        return spaces.Dict({k: batch_space(s, n) for k, s in space.spaces.items()})
    return spaces.Box(low=np.stack([space.low] * n), high=np.stack([space.high] * n),
                      dtype=space.dtype)


def empty_batch(space):
    """Zeros of a batched space: an array, or a dict of arrays for a Dict."""
    if isinstance(space, spaces.Dict):
        return {k: empty_batch(s) for k, s in space.spaces.items()}
    return np.zeros(space.shape, space.dtype)


def set_row(batch, i, obs):
    """batch[i] = obs, key by key for a dict observation."""
    if isinstance(batch, dict):
        for key, array in batch.items():
            array[i] = obs[key]
    else:
        batch[i] = obs


def copy_batch(batch):
    if isinstance(batch, dict):
        return {k: v.copy() for k, v in batch.items()}
    return batch.copy()


def _add_final(infos, obs, info, i, n):
    """same_step's infos["final_obs"][i] (an object array of the environments' last
    observations, arrays or dicts) and infos["final_info"] (vector layout), with their masks."""
    final = infos.get("final_obs")
    if final is None:
        final = infos["final_obs"] = np.full(n, None, dtype=object)
        infos["_final_obs"] = np.zeros(n, dtype=bool)
    final[i] = obs
    infos["_final_obs"][i] = True
    _add_info(infos, {"final_info": info}, i, n)


def _add_info(infos, info, i, n):
    """gymnasium's vector info layout: infos[k][i] = info[k], infos["_k"][i] = True."""
    for key, value in info.items():
        if isinstance(value, dict):
            sub = infos.get(key)
            if not isinstance(sub, dict):
                sub = infos[key] = {}
            _add_info(sub, value, i, n)
        else:
            array = infos.get(key)
            if array is None:
                if isinstance(value, (bool, np.bool_)):
                    array = np.zeros(n, dtype=bool)
                elif isinstance(value, (int, np.integer)):
                    array = np.zeros(n, dtype=np.int64)
                elif isinstance(value, (float, np.floating)):
                    array = np.zeros(n, dtype=np.float64)
                else:
                    array = np.full(n, None, dtype=object)
                infos[key] = array
            if array.dtype != object:
                kind = _kind(value)
                if kind not in "biuf" or "biuf".index(kind) > "biuf".index(array.dtype.kind):
                    # another type than the first env's: widen (never truncate)
                    array = infos[key] = array.astype(object if kind not in "biuf"
                                                      else np.float64 if kind == "f"
                                                      else np.int64)
            array[i] = value
        mask = infos.get("_" + key)
        if mask is None:
            mask = infos["_" + key] = np.zeros(n, dtype=bool)
        mask[i] = True


def _kind(value):
    """numpy's dtype kind of a scalar `value` ("O" if not a scalar), the usual Python
    numbers without asking numpy (an int that int64 holds is "i", as numpy makes it)."""
    t = type(value)
    if t is float:
        return "f"
    if t is bool:
        return "b"
    if t is int and -(1 << 63) <= value < (1 << 63):
        return "i"
    return np.asarray(value).dtype.kind if np.isscalar(value) else "O"
