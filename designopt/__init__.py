"""designopt: design a robot and its cell in one trajectory optimization.

Design parameters (DH lengths and twists) and the workpiece placement are *design joints*: joints whose
value is constant over the task. The library flows one way:
config -> DesignProblem -> transcription (TO / FK) -> Solution -> tables and plots.
"""

__version__ = "0.1.0"
