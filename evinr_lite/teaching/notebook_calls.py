"""How the notebooks call each exercise's function after its check: the call form the check then uses.

A cell runs ``exercises.use(name, fn)`` and a later cell calls what it returns, always in one form: some arguments
by position, some by keyword, the optional ones it does not need left out. The check calls the learner's function
that way too (:mod:`evinr_lite.teaching.checking.signature`): a signature that departs from the stub's passes where
the notebook's call works (``eps`` made keyword-only where the notebook leaves it out, a parameter renamed where the
notebook passes it by position), and fails, quoting the call below, where it does not. The table is read off the
notebooks (the first call of each exercise's function; cells counted from 1, markdown cells included) and
tests/test_exercise_wrong_solutions_round14.py keeps it in step with them.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class NotebookCall:
    """One exercise's call in a notebook: ``positional`` arguments by position (the stub's first ones, in its
    order), then ``keywords`` by name; every other parameter of the stub is left out."""

    notebook: str
    cell: int
    positional: int
    keywords: tuple[str, ...]
    text: str

    def where(self) -> str:
        return f"notebook {self.notebook}, cell {self.cell}"


NOTEBOOK_CALLS: dict[str, NotebookCall] = {
    'anchor': NotebookCall('05_regularization_and_tone_mapping', 31, 3, (), 'anchor_fn(L_seq - 3.0, g_, m_)'),
    'anchor_first_offset': NotebookCall('09_real_data', 33, 2, (), 'anchor_first_offset(scored.images[0], L_t0)'),
    'background_activity_filter': NotebookCall('11_your_own_recording', 28, 4, (), 'ba_filter(small.t, small.x, small.y, dt_small)'),
    'bisect_equal_count': NotebookCall('06_acceleration', 10, 2, (), 'bisect(events_short.t, stages[-1])'),
    'chain_offsets': NotebookCall('06_acceleration', 45, 2, (), 'chain(*accel.overlap_predictions(rec.model, rec.windows))'),
    'crossfade_weights': NotebookCall('06_acceleration', 31, 2, (), 'weights_fn(w_show, t_dense)'),
    'esim_interval': NotebookCall('02_events_from_video', 16, 6, (), 'step(L[k - 1], L[k], t[k - 1], t[k], ref, C)'),
    'estimate_contrast_threshold': NotebookCall('09_real_data', 13, 2, (), 'estimate_contrast_threshold(dL[mask], n[mask])'),
    'event_count_windows': NotebookCall('11_your_own_recording', 39, 2, (), 'count_windows(len(rec.events), MAX_EVENTS)'),
    'event_rate': NotebookCall('09_real_data', 8, 2, (), 'event_rate(events.t, span / 40)'),
    'event_rate_derivative': NotebookCall('01_event_generation_1d', 21, 4, (), 'rate(t_ev, p_ev, C, b)'),
    'events_to_frames_fixed': NotebookCall('02_events_from_video', 44, 3, (), 'to_frames(events, b_fixed, C)'),
    'frame_train_step': NotebookCall('04_frame_inr', 19, 6, (), 'step(model, opt, E, centers, durations, LAM)'),
    'grey_event_frame': NotebookCall('10_aed_demosaicing', 24, 5, (), 'grey_frame(first_half.x, first_half.y, first_half.p, C, RAW)'),
    'head_closed_form': NotebookCall('04_frame_inr', 49, 3, (), 'solve(A, E_flat, ridge)'),
    'highpass_per_event': NotebookCall('08_discussion_experiments', 13, 7, ('t_end',), 'hp_loop(noisy.t, noisy.x, noisy.y, noisy.p, SIZE, C, 2 * math.pi * cutoff_hz, t_end=DURATION)'),
    'hot_pixel_mask': NotebookCall('11_your_own_recording', 16, 4, (), 'hot_mask(rec.events.x, rec.events.y, (H, W), HOT_FACTOR)'),
    'integrate_events_1d': NotebookCall('01_event_generation_1d', 15, 4, (), 'integrate(t_ev, p_ev, C, t)'),
    'integrate_gradients': NotebookCall('05_regularization_and_tone_mapping', 51, 2, (), 'integrate(*grads(L_rec))'),
    'interval_imbalance': NotebookCall('02_events_from_video', 32, 1, (), 'mine(events_b)'),
    'offset_gradients': NotebookCall('05_regularization_and_tone_mapping', 51, 1, (), 'grads(L_rec)'),
    'pareto_front': NotebookCall('07_ablations', 47, 2, (), 'front_of(cost, quality)'),
    'quad_bayer_channel': NotebookCall('10_aed_demosaicing', 9, 3, (), 'channel(y, x, phase)'),
    'reinhard_tonemap': NotebookCall('05_regularization_and_tone_mapping', 41, 2, (), 'tonemap(L_frame, g)'),
    'render_event_counts': NotebookCall('08_discussion_experiments', 19, 2, (), 'render(scene.log_intensity(bounds), C)'),
    'sine_layer_derivative': NotebookCall('04_frame_inr', 13, 5, (), 'layer(tau, dtau_dt, model.weights[0][0], model.biases[0][0, 0], model.first_omega_0)'),
    'split_index': NotebookCall('03_coordinate_inr', 22, 2, (), 'split(k, SIZE)'),
    'temporal_loss': NotebookCall('01_event_generation_1d', 32, 3, (), 'loss_fn(dF_dt, delta_L, durations)'),
    'temporal_loss_boundary': NotebookCall('04_frame_inr', 35, 2, (), 'boundary_loss(F_b, E[0])'),
    'tikhonov_autograd': NotebookCall('03_coordinate_inr', 22, 2, (), 'tikhonov(dF_dx, dF_dy)'),
    'time_fps_products': NotebookCall('07_ablations', 10, 1, (), 'products_of(table)'),
    'total_variation': NotebookCall('05_regularization_and_tone_mapping', 11, 1, (), 'tv(F)'),
}
"""{exercise name: its call in the notebooks}; `chain(*pairs)` and `integrate(*grads(...))` unpack two arguments."""
