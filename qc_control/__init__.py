"""qc_control: quarter-car suspension models on python-control."""
from .model import QuarterCarParams, quarter_car, load_config, read_config, STATES, OUTPUTS
from .modal import Mode, ModalAnalysis, modal_analysis

__version__ = "0.1.0"
__all__ = ["QuarterCarParams", "quarter_car", "load_config", "read_config", "STATES", "OUTPUTS",
           "Mode", "ModalAnalysis", "modal_analysis"]
