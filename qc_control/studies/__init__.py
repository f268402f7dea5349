"""Studies that run many responses: the method comparison (`compare`),
design sweeps (`sweeps`, with nonlinear designs stepped together in
`nlsweep`), damper optimisation (`damping`) and the controller comparison
(`control_study`)."""
