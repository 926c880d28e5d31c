"""The run: its configuration and coercion, its parts resolved once, the closed loop and the batch engine with
its compiled law, certificates and designs, and many runs at once. What asks for runs sits above it: the
searches (:mod:`wmr_mj.searches`) and the experiments (:mod:`wmr_mj.experiments`)."""
