"""Scores: metrics, LPIPS, the one scoring path, what an MSE is made of, ablation tables, event enhancement."""
from .metrics import mse, ssim, equalize, score_pairs, score_frames, protocol_description, SCORE_PROTOCOLS, SSIM_PROTOCOL
from .scoring import (evaluate, results_table, score_sequence, match_frames, pool, frames_to_score, measure_inference_fps,
                      resolve_lpips)
from .level import match_level, error_parts
from . import ablation, enhance, lpips

__all__ = ["mse", "ssim", "equalize", "score_pairs", "score_frames", "protocol_description", "SCORE_PROTOCOLS",
           "evaluate", "results_table", "score_sequence", "match_frames", "pool", "frames_to_score",
           "measure_inference_fps", "ablation", "enhance", "lpips", "SSIM_PROTOCOL", "resolve_lpips",
           "match_level", "error_parts"]
