"""The analysis: the paper's section 4, the certificate for the controller actually run, verdicts."""
