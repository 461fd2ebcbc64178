"""The impact laws: one module per law, each registering itself in `lawbench.law.LAWS`."""
