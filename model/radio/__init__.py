"""The radio: coverage in integers (the same ticks on every CPU, so a delta can travel as its sensing event),
who hears whom, local planning's members."""
