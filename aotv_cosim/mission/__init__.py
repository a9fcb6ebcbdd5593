"""What a run achieved: its exit orbit (apogee, perigee), the capture class against the target
band and the correction dv (`outcome`), as summary entries of one run and columns of a campaign
row (`outcome_rows`). Plain functions over recorded values; physics only below it."""
