function ok = same_bits(want_bits, got)
% SAME_BITS  Per row: every value of single `got` has the bits `want_bits` (uint32), or
% both are NaN.
got_bits = reshape(typecast(reshape(got, 1, []), 'uint32'), size(got));
want = reshape(typecast(reshape(want_bits, 1, []), 'single'), size(want_bits));
ok = all(got_bits == want_bits | (isnan(want) & isnan(got)), 2);
end
