"""Learned policies: single-agent wrappers, SB3 training, self-play and the model zoo.

* :class:`SingleAgentEnv` -- one role of ``surveillance_v1`` as a Gymnasium env, the
  other played by a fixed Policy;
* :class:`TrainConfig`, :func:`load_config` -- a run's validated config (TOML);
* :func:`train`, :func:`train_from_config` -- SB3 PPO/SAC with checkpoints, resume and
  provenance; :func:`evaluate_model` -- a model's success rate against an opponent;
* :func:`self_play` -- alternating pursuer/evader rounds;
* :mod:`training.zoo` -- shipped models (``zoo.list_models()``, ``zoo.load(name)``);
* :func:`cli_train` -- the ``surveil train`` command.

SB3 and torch are imported only when a model is built or loaded.
"""

from training.cli import add_train_arguments, cli_train, run_train
from training.config import ALGORITHMS, TrainConfig, load_config
from training.selfplay import SelfPlayResult, self_play
from training.single_agent import SingleAgentEnv, make_opponent
from training.train import (
    ENV_NAME,
    EvalResult,
    TrainResult,
    evaluate_model,
    latest_checkpoint,
    load_policy,
    read_provenance,
    train,
    train_from_config,
)

__all__ = [
    "ALGORITHMS",
    "ENV_NAME",
    "EvalResult",
    "SelfPlayResult",
    "SingleAgentEnv",
    "TrainConfig",
    "TrainResult",
    "add_train_arguments",
    "cli_train",
    "evaluate_model",
    "latest_checkpoint",
    "load_config",
    "load_policy",
    "make_opponent",
    "read_provenance",
    "run_train",
    "self_play",
    "train",
    "train_from_config",
]
