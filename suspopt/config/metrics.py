"""Metric specs in YAML (the ``metrics:`` list; later objectives and constraints reuse them)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, PrivateAttr, field_validator, model_validator

from .. import user_metrics
from ..specs import METRICS
from .base import Duration, Section, bounds

__all__ = ["MetricSpec"]


class MetricSpec(Section):
    """One metric of one signal (or of a per-corner signal family), see suspopt.metrics.specs."""

    name: str | None = Field(None, description="name under /metrics (default metric.signal)")
    metric: str = Field(
        description="one of: "
        + ", ".join(METRICS)
        + "; or a user metric (suspopt.metric, docs/guide/custom-metrics.md)"
    )
    signal: str | None = Field(
        None,
        description="signal name (body.heave_acc) or per-corner "
        "family (travel, tyre_deflection, ...)",
    )
    corners: list[str] | None = Field(None, description="corners of a family (default all)")
    reduce: Literal["none", "mean", "max", "min", "sum"] = Field(
        "none", description="combine the corners' values into one (none: one per corner)"
    )
    weighting: Literal["Wk", "Wd", "Wf", "Wc", "We", "Wj"] | None = Field(
        None,
        description="ISO 2631-1 frequency weighting for rms_weighted, vdv, mtvv, "
        "crest_factor (none: unweighted)",
    )
    tau: Duration = Field(1.0, description="running r.m.s. integration time for mtvv [s]")
    band: Annotated[float, bounds(0.0, 1.0, closed=False)] = Field(
        0.02, description="settling band for transient metrics [-]"
    )

    @field_validator("metric")
    @classmethod
    def _known_metric(cls, metric: str | None) -> str | None:
        return metric if metric is None else user_metrics.check_metric(metric)

    #: Where a user metric came from (:class:`suspopt.user_metrics.Source`; None for a
    #: built-in): it goes with the spec to the workers, which register the metric from it.
    _source: user_metrics.Source | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _user_metric_source(self) -> MetricSpec:
        self._source = user_metrics.source(self.metric)
        return self
