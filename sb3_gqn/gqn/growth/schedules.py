"""When to open the next, finer level of nested bins (paper section 4).

* :func:`nested_bin_levels` lists the resolutions, e.g. ``3 -> 5 -> 9`` (the default ``bins=(3, 9)``) or the
  paper's ``2 -> 3 -> 5 -> 9`` (each level doubles the number of intervals between the action bounds).
* ``growth="linear"``: :func:`linear_growth_level` opens level ``g`` (0-based, level 0 is
  active from the start) once ``g / (N + 1)`` of the total timesteps have passed, ``N`` being the
  number of levels.
* ``growth="adaptive"``: :class:`AdaptiveGrowth` keeps a moving window of returns and grows when
  the current return falls below the threshold of paper eq. 4 (:func:`adaptive_threshold`), or when
  the returns have stopped improving (:func:`plateau`, which eq. 4 cannot see: a flat return has
  ``sigma = 0`` and never falls below ``0.95 mu``).
* ``growth_kwargs=dict(init="interpolate")``: :func:`interpolation_neighbours` says which two active bins each
  newly opened bin is warm-started from.
* ``growth_kwargs=dict(probation=k)`` (adaptive growth): a level the schedule opens is explored at once, but the agent
  keeps acting greedily and bootstrapping on the deployed level until a greedy episode over the new one holds the
  return (:func:`probation_holds`); see :class:`AdaptiveGrowth`.

:func:`growth_settings` turns GQN's ``growth`` and ``growth_kwargs`` into the warm start and the schedule's state.

:class:`~sb3_gqn.gqn.growth.callback.GrowthCallback` drives either schedule during ``learn()``.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, field, fields
from typing import Any, ClassVar, TypeGuard

import numpy as np
from gymnasium import spaces

from sb3_gqn.common.arguments import check_choice, check_int, check_number

GROWTH_SCHEDULES = ("adaptive", "linear", None)
#: How a newly opened bin's head row starts: the mean of its two nested neighbours' (``"interpolate"``, the default)
#: or as it is (``"none"``, the paper); ``growth_kwargs["init"]``, for every schedule and for ``grow()`` by hand
GROWTH_INITS = ("interpolate", "none")
DEFAULT_GROWTH_INIT = "interpolate"
RETURN_SOURCES = ("evaluation", "training")
#: The adaptive schedule's default cadence: one greedy reading every 5 % of the run's budget (2 500 env steps of a
#: 50k-step run, the cadence of the schedule before it read the budget); its window and patience, counted in readings,
#: are then fractions of the budget too
DEFAULT_EVAL_FRACTION = 0.05


#: The most bins per action dimension GQN and DecQN take (``bins``, and the choices of a ``Discrete`` or
#: ``MultiDiscrete`` action space): ``2 ** 10 + 1``, a nested level (ten doublings above 2 bins, four above the
#: paper's finest resolution, 65 bins in its Meta-World setting), whose neighbouring bins are 1/1024 of the action range
#: apart. The critic's head then holds at most ``1025 * action_dims`` outputs (0.5M weights per action dimension on a
#: 512-wide torso, each copied into the target and acting networks and the optimizer's state); beyond the limit a typo
#: such as ``bins=10**9`` would allocate until memory runs out instead of failing.
MAX_BINS = 1025


def _is_bin_count(value: object) -> TypeGuard[int | np.integer]:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def nested_bin_levels(initial: int, final: int) -> list[int]:
    """The nested resolutions from ``initial`` to ``final`` bins per dimension.

    Each level doubles the number of intervals: ``n -> 2 n - 1``. ``(2, 9)`` gives
    ``[2, 3, 5, 9]``, ``(9, 65)`` gives ``[9, 17, 33, 65]``, ``(3, 9)`` gives ``[3, 5, 9]``,
    ``(9, 9)`` gives ``[9]``.

    :raises ValueError: naming ``bins``, if either is not an integer (``2.0``, ``"9"``, ``True``), either is below 2,
        ``final`` exceeds :data:`MAX_BINS`, or ``final`` cannot be reached by doubling from ``initial`` (e.g. ``(2, 8)``
        or ``(4, 9)``); before anything is allocated
    """
    for name, value in (("initial", initial), ("final", final)):
        if not _is_bin_count(value):
            raise ValueError(f"bins must be integers >= 2, got {name}={value!r} ({type(value).__name__})")
    initial, final = int(initial), int(final)
    if initial < 2:
        raise ValueError(f"bins: the coarsest level needs at least 2 bins per dimension, got {initial}")
    if final < initial:
        raise ValueError(f"bins=({initial}, {final}): the final resolution must not be below the initial one")
    if final > MAX_BINS:
        raise ValueError(
            f"bins: at most MAX_BINS={MAX_BINS} bins per action dimension (four doublings above the paper's finest, 65), "
            f"got {final}"
        )
    levels = [initial]
    while levels[-1] < final:
        levels.append(2 * levels[-1] - 1)
    if levels[-1] != final:
        raise ValueError(
            f"bins=({initial}, {final}) cannot be nested: doubling the intervals from {initial} bins gives "
            f"{levels[:-1]} then {levels[-1]}, never {final}. Valid pairs are e.g. (2, 9), (3, 9), (9, 65)."
        )
    return levels


def bin_levels_from(bins: int | tuple[int, int] | list[int]) -> list[int]:
    """``9`` -> ``[9]`` (static); ``(2, 9)`` -> ``[2, 3, 5, 9]`` (see :func:`nested_bin_levels`).

    :raises ValueError: naming ``bins`` for anything else: ``"9"``, ``2.5``, ``True``, ``None``, ``(2, 5, 9)``,
        ``(2.0, 9)``, more than :data:`MAX_BINS`, or bins that cannot nest
    """
    if _is_bin_count(bins):
        return nested_bin_levels(int(bins), int(bins))
    if isinstance(bins, (tuple, list)) and len(bins) == 2:
        return nested_bin_levels(bins[0], bins[1])
    raise ValueError(f"bins must be an int >= 2 or an (initial, final) pair of ints, got {bins!r}")


def checked_bins(bins: int | tuple[int, int] | list[int]) -> int | tuple[int, int]:
    """``bins`` checked (:func:`bin_levels_from`) and normalized to Python ints: ``np.int64(9)`` -> ``9``,
    ``[np.int64(3), 9]`` -> ``(3, 9)``."""
    levels = bin_levels_from(bins)
    return levels[0] if _is_bin_count(bins) else (levels[0], levels[-1])


#: the class default's first level: for a ``Box`` it holds the zero action, and it starts the discrete default too
DEFAULT_INITIAL_BINS = 3


def check_action_choices(action_space: spaces.Space) -> None:
    """Refuse a ``Discrete`` or ``MultiDiscrete`` action space with more than :data:`MAX_BINS` choices per dimension
    (the critic's head would hold one output per choice), with a ``ValueError`` naming it, before anything is built.
    Other spaces pass (a ``Box`` is discretized to ``bins``, checked on their own)."""
    if isinstance(action_space, spaces.Discrete):
        choices = int(action_space.n)
    elif isinstance(action_space, spaces.MultiDiscrete):
        choices = int(np.max(action_space.nvec)) if np.size(action_space.nvec) else 0
    else:
        return
    if choices > MAX_BINS:
        raise ValueError(
            f"the env's action space {action_space} has {choices} choices per dimension: GQN and DecQN take at most "
            f"MAX_BINS={MAX_BINS} (one output of the critic's head per choice)"
        )


def default_bins(action_space: spaces.Space) -> tuple[int | tuple[int, int], bool]:
    """``bins`` for ``action_space`` when none are given, and whether they grow (more than one level).

    - ``Box``: ``(3, 9)``, the class default.
    - ``Discrete(n)`` or ``MultiDiscrete([n] * M)``: the env's own ``n`` choices. When ``n`` is a nested level count
      above the first level (5, 9, 17, 33, 65, ...: ``n - 1`` a power of two) they grow from 3 bins, ``(3, n)``;
      otherwise (2, 3, 4, 6, 7, ...) ``n`` is a static resolution. ``CartPole-v1`` (``Discrete(2)``) gets ``2``,
      ``Acrobot-v1`` (``Discrete(3)``) ``3``, ``MultiDiscrete([9, 9])`` ``(3, 9)``.
    - Any other space (an uneven ``MultiDiscrete`` too): ``(3, 9)``; the action-space check then says what is wrong.

    :raises ValueError: for more than :data:`MAX_BINS` choices per dimension (:func:`check_action_choices`)
    """
    check_action_choices(action_space)
    choices: int | None = None
    if isinstance(action_space, spaces.Discrete):
        choices = int(action_space.n)
    elif isinstance(action_space, spaces.MultiDiscrete):
        counts = set(np.ravel(action_space.nvec).tolist())
        choices = int(counts.pop()) if len(counts) == 1 else None
    if choices is None:
        return (DEFAULT_INITIAL_BINS, 9), True
    if choices > DEFAULT_INITIAL_BINS and ((choices - 1) & (choices - 2)) == 0:
        return (DEFAULT_INITIAL_BINS, choices), True
    return choices, False


def adaptive_threshold(mean: float, std: float) -> float:
    """Paper eq. 4: ``(1 - 0.05 sgn(mu)) mu + 0.9 sigma``.

    ``mean`` and ``std`` are the moving-window mean and standard deviation of past returns;
    growth happens when the current return falls below this value (stagnation).
    """
    return (1.0 - 0.05 * float(np.sign(mean))) * mean + 0.9 * std


def plateau(returns: list[float], patience: int, min_improvement: float = 0.05) -> bool:
    """Patience rule: the last ``patience`` returns did not improve on the best return before them.

    An improvement must exceed ``min_improvement * |best|`` (5 % by default, the margin eq. 4 uses), so
    evaluation noise around a flat return does not count as progress. Needs ``patience + 1`` returns.
    ``[-1000, -1000, -1000]`` with ``patience=2`` is a plateau; ``[10, 50, 52]`` is one (52 < 50 * 1.05);
    ``[10, 50, 60]`` is not.

    :param returns: returns since the last growth, oldest first
    :param patience: evaluations without improvement before the rule fires
    :param min_improvement: relative margin an improvement must exceed
    """
    if patience < 1 or len(returns) < patience + 1:
        return False
    best_before = max(returns[:-patience])
    return max(returns[-patience:]) <= best_before + min_improvement * abs(best_before)


def probation_holds(reference: float, candidate: float, tolerance: float = 0.3) -> bool:
    """Whether a greedy return at a newly opened level holds the deployed level's: ``candidate`` is at least
    ``reference - tolerance * |reference|`` (70 % of a positive reference by default, 130 % of a negative one).

    ``probation_holds(300, 210)`` is True, ``(300, 209)`` False, ``(-100, -130)`` True, ``(-100, -131)`` False,
    ``(45, 0)`` False (a policy that stands still after earning 45), ``(0, 0)`` True.

    :param reference: the deployed level's last greedy return (the one the growth was decided on)
    :param candidate: a greedy return over the opened level
    :param tolerance: the relative drop that still holds
    """
    return candidate >= reference - tolerance * abs(reference)


def interpolation_neighbours(max_bins: int, previous_bins: int, active_bins: int) -> list[tuple[int, int, int]]:
    """The bins one growth step opens, each with its two nested neighbours: ``(new, left, right)``.

    Opening level ``active_bins`` from ``previous_bins`` (one doubling) halves the stride between active
    bins; each new bin sits midway between two previously active ones. With 9 bins: 2 -> 3 opens bin 4
    between 0 and 8; 3 -> 5 opens 2 (0, 4) and 6 (4, 8).

    :raises ValueError: if ``active_bins`` is not the next nested level after ``previous_bins``
    """
    if active_bins != 2 * previous_bins - 1 or (max_bins - 1) % (active_bins - 1) != 0:
        raise ValueError(f"{previous_bins} -> {active_bins} bins (of {max_bins}) is not one nested growth step")
    stride = (max_bins - 1) // (active_bins - 1)
    return [(new, new - stride, new + stride) for new in range(stride, max_bins - 1, 2 * stride)]


def linear_growth_level(num_timesteps: int, total_timesteps: int, n_levels: int) -> int:
    """Level index the linear schedule has reached: level ``g`` opens at ``g / (N + 1)`` of training.

    With ``N = 4`` levels and 100 000 total steps, levels 1, 2, 3 open at 20 000, 40 000, 60 000.
    """
    if total_timesteps <= 0:
        return 0
    reached = math.floor(num_timesteps * (n_levels + 1) / total_timesteps)
    return max(0, min(n_levels - 1, reached))


@dataclass
class GrowthDecision:
    """Outcome of one adaptive check: the compared return, the eq. 4 threshold (None while the window
    fills), when ``grow`` which rule fired (``"eq. 4"`` or ``"plateau"``), and when the return was a probation
    return (``probation_reference`` set) whether the opened level is deployed."""

    current_return: float
    threshold: float | None
    window_mean: float | None
    window_std: float | None
    grow: bool
    rule: str | None = None
    deploy: bool = False
    probation_reference: float | None = None

    def describe(self) -> str:
        """One line for the console and the log."""
        if self.rule == "plateau":
            return f"return {self.current_return:.2f} stopped improving (plateau)"
        return f"return {self.current_return:.2f} < eq. 4 threshold {self.threshold:.2f}"

    def describe_probation(self) -> str:
        """One line for a probation return: held, or deployed after the last allowed try."""
        assert self.probation_reference is not None, "a probation decision has the opened level's reference return"
        held = "holds" if probation_holds(self.probation_reference, self.current_return) else "misses, last try"
        return f"probation return {self.current_return:.2f} {held} against {self.probation_reference:.2f}"


@dataclass
class AdaptiveGrowth:
    """State of the adaptive schedule (saved with the model).

    Returns come either from greedy evaluation episodes (``returns_source="evaluation"``) or from
    every finished training episode (``"training"``). Evaluation episodes are interleaved with
    training: every ``eval_fraction`` of the run's budget (5 %: every 2 500 env steps of a 50k-step run, every 50 000
    of a 1M-step run) or every ``eval_freq`` env steps when that is given, the next ``eval_episodes`` episodes that start
    act greedily over the active bins (no epsilon). Their transitions still go to the replay buffer
    and count as environment steps, so no separate evaluation env or extra budget is needed, and it
    works for any env, wrapper stack or VecEnv that GQN trains on.

    Two rules decide, after every return, whether the next level opens:

    * eq. 4 (:func:`adaptive_threshold`): the window holds the last ``window`` returns since the most
      recent growth; once it is full, a return below the threshold grows;
    * the plateau rule (:func:`plateau`): ``patience`` returns in a row without a ``min_improvement``
      gain on the best return of the level grow. ``patience=None`` leaves eq. 4 alone (the paper as
      written).

    After a growth both restart, so the new level is judged on its own returns and one dip cannot
    cascade through all levels.

    With ``probation`` (an int), an opened level is explored at once, but greedy actions and the TD target's max
    stay on the deployed level (the opened bins learn "this bin, then the deployed policy"): the evaluation
    episodes, which act greedily over the opened level, are its probation. The first whose return holds against
    the deployed level's last return (:func:`probation_holds`), or the ``probation``-th in any case, deploys it. A
    level opened at the first decision that can grow is deployed one evaluation later if it holds. The growth rules
    read the evaluation returns as without probation. With ``returns_source="training"`` no episode acts greedily
    over the opened level, so the first training return that holds deploys it (usually the next one).

    GQN builds it from ``growth_kwargs`` (:func:`growth_settings`): its settings are the first seven fields
    (:attr:`SETTINGS`), the others the state that ``learn()`` moves on and ``save`` keeps.

    The cadence reads the budget: with ``eval_fraction`` (the default), the readings, and so the window and the
    patience (counted in readings) and the least time at a level (``max(window + 1, patience + 1)`` readings), are
    fractions of the run's ``total_timesteps``, which the first ``learn()`` fixes (:attr:`budget`, saved with the
    model). ``learn(..., reset_num_timesteps=False)`` and resumed runs keep it; ``learn()`` with a reset counter is a
    new run with its own budget. ``eval_episodes`` stays a count of episodes (an episode's length does not scale with
    the budget).

    :param eval_freq: environment steps between greedy evaluations, which are interleaved in training (their
        transitions are stored and count as steps); ``None`` (the default): ``eval_fraction`` of the budget
    :param eval_fraction: the fraction of the run's budget between greedy evaluations (``0.05`` when neither it nor
        ``eval_freq`` is given); give one of the two
    :param eval_episodes: greedy episodes averaged into one evaluation return
    :param window: number of past returns in eq. 4's moving mean and standard deviation
    :param returns_source: ``"evaluation"`` (greedy episodes) or ``"training"`` (every finished training episode)
    :param patience: returns in a row without a ``min_improvement`` gain before the plateau rule grows (it sees the
        flat plateaus eq. 4 cannot); ``None``: eq. 4 alone
    :param min_improvement: relative gain over the level's best return that counts as an improvement for the plateau
        rule
    :param probation: ``None`` deploys a level when it opens (the paper as written); an int ``k`` keeps greedy actions
        and the TD target's max on the deployed level until a greedy episode over the opened one holds 70 % of its
        return, at most ``k`` tries
    """

    #: The schedule's settings (``growth_kwargs`` keys besides ``init``); the other fields are its state
    SETTINGS: ClassVar[tuple[str, ...]] = (
        "eval_freq",
        "eval_fraction",
        "eval_episodes",
        "window",
        "returns_source",
        "patience",
        "min_improvement",
        "probation",
    )
    #: What a schedule saved before a field existed ran with, where it is not the field's default: models saved
    #: before the plateau rule ran eq. 4 alone, and before the cadence read the budget every ``eval_freq`` steps
    #: (fields missing from this table take their defaults)
    BEFORE_FIELD: ClassVar[dict[str, Any]] = {"patience": None, "eval_fraction": None}

    eval_freq: int | None = None
    eval_fraction: float | None = None
    eval_episodes: int = 1
    window: int = 3
    returns_source: str = "evaluation"
    patience: int | None = 2
    min_improvement: float = 0.05
    probation: int | None = None
    probation_reference: float | None = None
    probation_tries: int = 0
    #: env steps of the run the cadence is a fraction of (set by ``learn()``; ``None`` before the first)
    budget: int | None = None
    history: list[float] = field(default_factory=list)
    level_returns: list[float] = field(default_factory=list)
    next_eval_step: int = 0
    pending_episodes: int = 0
    finished_eval_returns: list[float] = field(default_factory=list)
    greedy_envs: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    episode_returns: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        # The constructor's own checks (sb3_gqn.common.arguments), under the names GQN's growth_kwargs carry
        check_choice("growth_kwargs['returns_source']", self.returns_source, RETURN_SOURCES)
        if self.eval_freq is not None and self.eval_fraction is not None:
            raise ValueError(
                f"growth_kwargs sets both eval_freq={self.eval_freq!r} (env steps) and eval_fraction="
                f"{self.eval_fraction!r} (of the budget) for the adaptive schedule's cadence: give one of them"
            )
        if self.eval_freq is not None:
            self.eval_freq = check_int("growth_kwargs['eval_freq']", self.eval_freq, 1)
        else:
            fraction = DEFAULT_EVAL_FRACTION if self.eval_fraction is None else self.eval_fraction
            self.eval_fraction = check_number("growth_kwargs['eval_fraction']", fraction, 0.0)
            if not 0.0 < self.eval_fraction <= 1.0:
                raise ValueError(
                    f"growth_kwargs['eval_fraction'] must be in (0, 1] (a fraction of the run's budget), got {fraction!r}"
                )
        self.eval_episodes = check_int("growth_kwargs['eval_episodes']", self.eval_episodes, 1)
        self.window = check_int("growth_kwargs['window']", self.window, 1)
        if self.patience is not None:
            self.patience = check_int("growth_kwargs['patience']", self.patience, 1)
        self.min_improvement = check_number("growth_kwargs['min_improvement']", self.min_improvement, 0.0)
        if self.probation is not None:
            self.probation = check_int("growth_kwargs['probation']", self.probation, 1)

    @property
    def steps_between_readings(self) -> int:
        """Env steps between greedy readings: ``eval_freq``, or ``eval_fraction`` of :attr:`budget` (at least 1;
        before the first ``learn()`` fixes the budget, of a 50k-step run)."""
        if self.eval_freq is not None:
            return self.eval_freq
        assert self.eval_fraction is not None, "__post_init__ sets one of eval_freq and eval_fraction"
        budget = 50_000 if self.budget is None else self.budget
        return max(1, round(self.eval_fraction * budget))

    def __setstate__(self, state: dict[str, Any]) -> None:
        # Schedules saved before a field existed (0.1.0 had no plateau rule and no probation): what they ran with
        # (BEFORE_FIELD), else the field's default; the level's returns start from the window
        state.setdefault("level_returns", list(state.get("history", [])))
        for item in fields(self):
            if item.name not in state:
                factory = item.default_factory
                default = factory() if item.default is MISSING and callable(factory) else item.default
                state[item.name] = self.BEFORE_FIELD.get(item.name, default)
        self.__dict__.update(state)

    def settings(self) -> dict[str, Any]:
        """The schedule's settings (:attr:`SETTINGS`) by name, as ``growth_kwargs`` writes them."""
        return {name: getattr(self, name) for name in self.SETTINGS}

    def change_settings(self, **settings: Any) -> None:
        """Change settings (``load(path, growth_kwargs=...)``), checked as the constructor checks them; the state goes
        on. A new ``eval_freq`` replaces the cadence's ``eval_fraction`` and the other way round. ``ValueError``
        naming a key that is not a setting."""
        check_growth_keys(settings, self.SETTINGS)
        current = self.settings()
        for given, other in (("eval_freq", "eval_fraction"), ("eval_fraction", "eval_freq")):
            if settings.get(given) is not None and other not in settings:
                current[other] = None
        checked = AdaptiveGrowth(**{**current, **settings})
        for name in self.SETTINGS:
            setattr(self, name, getattr(checked, name))

    @property
    def on_probation(self) -> bool:
        """Whether an opened level waits to be deployed."""
        return self.probation_reference is not None

    def start(
        self, n_envs: int, env_was_reset: bool, num_timesteps: int = 0, budget: int | None = None, new_run: bool = True
    ) -> None:
        """Prepare per-env bookkeeping at the start of ``learn()``.

        A new run (``new_run``: ``learn()`` with ``reset_num_timesteps=True``) fixes :attr:`budget` to its ``budget``
        (its ``total_timesteps``); a continued one (``reset_num_timesteps=False``, a resumed run) keeps the budget fixed
        before, and takes ``budget`` only when none is. A run of no steps (``learn(0)``) fixes none: the cadence of
        a run continued after it reads that run's budget. When the env was reset (new run, ``set_env``, load), the
        episodes in progress are gone: their partial returns are dropped and greedy evaluation episodes that were
        running are started again. A run whose step counter was reset evaluates one cadence on.
        """
        if budget is not None and (new_run or not self.budget):
            self.budget = int(budget) if budget > 0 else None
        cadence = self.steps_between_readings
        if self.next_eval_step == 0 or self.next_eval_step > num_timesteps + cadence:
            self.next_eval_step = num_timesteps + cadence
        if env_was_reset or len(self.greedy_envs) != n_envs:
            self.pending_episodes += int(self.greedy_envs.sum())
            self.greedy_envs = np.zeros(n_envs, dtype=bool)
            self.episode_returns = np.zeros(n_envs, dtype=np.float64)
            for env_idx in range(n_envs):
                self._start_episode(env_idx)

    def _start_episode(self, env_idx: int) -> None:
        if self.pending_episodes > 0:
            self.greedy_envs[env_idx] = True
            self.pending_episodes -= 1

    def observe(self, rewards: np.ndarray, dones: np.ndarray, num_timesteps: int) -> list[GrowthDecision]:
        """Account one vectorised env step; return the decisions made at episodes that just ended."""
        evaluating = self.returns_source == "evaluation"
        if self.next_eval_step == 0:  # observed before start(): the first reading one cadence on
            self.next_eval_step = self.steps_between_readings
        if evaluating and num_timesteps >= self.next_eval_step:
            cadence = self.steps_between_readings
            self.next_eval_step = (num_timesteps // cadence + 1) * cadence
            if self.pending_episodes == 0 and not self.greedy_envs.any() and not self.finished_eval_returns:
                self.pending_episodes = self.eval_episodes
        self.episode_returns += rewards
        decisions = []
        for env_idx in np.flatnonzero(dones):
            episode_return = float(self.episode_returns[env_idx])
            self.episode_returns[env_idx] = 0.0
            if not evaluating:
                decisions.append(self.decide(episode_return))
            elif self.greedy_envs[env_idx]:
                self.greedy_envs[env_idx] = False
                self.finished_eval_returns.append(episode_return)
                if len(self.finished_eval_returns) == self.eval_episodes:
                    decisions.append(self.decide(float(np.mean(self.finished_eval_returns))))
                    self.finished_eval_returns = []
            self._start_episode(int(env_idx))
        return decisions

    def decide(self, current_return: float) -> GrowthDecision:
        """Apply eq. 4 over the window and the plateau rule over the level's returns; grow if either fires.

        While a level is on probation the return is also its probation return: ``deploy`` when it holds or the
        tries are used up. The growth rules are the same with or without probation; a growth that happens starts
        its probation through :meth:`start_probation`.
        """
        deploy, reference = False, self.probation_reference
        if reference is not None:
            self.probation_tries += 1
            deploy = probation_holds(reference, current_return) or self.probation_tries >= (self.probation or 1)
            if deploy:
                self.probation_reference, self.probation_tries = None, 0
        self.level_returns.append(current_return)
        threshold = window_mean = window_std = None
        rule = None
        if len(self.history) >= self.window:
            window_mean = float(np.mean(self.history))
            window_std = float(np.std(self.history))
            threshold = adaptive_threshold(window_mean, window_std)
            if current_return < threshold:
                rule = "eq. 4"
        if rule is None and self.patience is not None and plateau(self.level_returns, self.patience, self.min_improvement):
            rule = "plateau"
        if rule is not None:
            self.history = []
            self.level_returns = []
        else:
            self.history = [*self.history, current_return][-self.window :]
        return GrowthDecision(
            current_return, threshold, window_mean, window_std, grow=rule is not None, rule=rule, deploy=deploy,
            probation_reference=reference,
        )  # fmt: skip

    def start_probation(self, reference: float) -> None:
        """A level was opened after a decision on ``reference`` (the deployed level's return): its probation starts,
        unless an earlier opened level is still on probation (then that one's reference and tries carry on, and the
        first return that holds deploys both)."""
        if self.probation is not None and self.probation_reference is None:
            self.probation_reference, self.probation_tries = float(reference), 0

    def end_probation(self) -> None:
        """Forget a running probation (the level was deployed by other means, e.g. ``model.grow()`` by hand)."""
        self.probation_reference, self.probation_tries = None, 0

    def stop_evaluating(self) -> None:
        """No further levels: stop scheduling greedy episodes."""
        self.pending_episodes = 0
        self.finished_eval_returns = []
        self.greedy_envs[:] = False


def check_growth_keys(growth_kwargs: dict[str, Any], valid: tuple[str, ...]) -> None:
    """``ValueError`` naming the keys of ``growth_kwargs`` that are not in ``valid``."""
    unknown = sorted(str(key) for key in growth_kwargs if key not in valid)
    if unknown:
        raise ValueError(f"growth_kwargs has no setting {', '.join(map(repr, unknown))}: its keys are {valid}")


def growth_settings(growth: str | None, growth_kwargs: dict[str, Any] | None) -> tuple[str, AdaptiveGrowth | None]:
    """GQN's ``growth`` and ``growth_kwargs`` checked: the warm start of opened bins (``growth_kwargs["init"]``,
    :data:`DEFAULT_GROWTH_INIT` when not given) and, for ``growth="adaptive"``, the schedule built from the other keys
    (:class:`AdaptiveGrowth`'s settings; its defaults where not given).

    The adaptive schedule's settings are read only by ``growth="adaptive"``: with ``growth="linear"`` or ``None`` (where
    only ``grow()`` by hand opens levels, reading ``init``) they are refused by name.

    :raises ValueError: naming ``growth`` or the ``growth_kwargs`` key that is wrong or not read
    """
    check_choice("growth", growth, GROWTH_SCHEDULES)
    if growth_kwargs is not None and not isinstance(growth_kwargs, dict):
        raise ValueError(f"growth_kwargs must be a dict (or None), got {growth_kwargs!r}")
    settings = dict(growth_kwargs or {})
    check_growth_keys(settings, ("init", *AdaptiveGrowth.SETTINGS))
    read = ("init", *AdaptiveGrowth.SETTINGS) if growth == "adaptive" else ("init",)
    unread = sorted(str(key) for key in settings if key not in read)
    if unread:
        reads = f"reads only {', '.join(map(repr, read))}"
        raise ValueError(
            f"growth_kwargs {', '.join(map(repr, unread))} would be ignored: growth={growth!r} {reads} "
            "(the adaptive schedule's settings need growth='adaptive')"
        )
    init = settings.pop("init", DEFAULT_GROWTH_INIT)
    check_choice("growth_kwargs['init']", init, GROWTH_INITS)
    schedule = AdaptiveGrowth(**settings)
    return init, schedule if growth == "adaptive" else None
