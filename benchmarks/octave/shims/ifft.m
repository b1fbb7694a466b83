function y = ifft(x, varargin)
% IFFT  MATLAB's ifft(..., 'symmetric') for GNU Octave, whose ifft has no such flag: the inverse
% transform of the conjugate-symmetric completion of x's first half (x(1) and, for an even
% length, the middle term taken real), which is real; without the flag, the builtin ifft.
% ECO's scale filter calls ifft(X, 'symmetric') on a 1 x n row.
  sym = cellfun(@(a) ischar(a) && strcmp(a, 'symmetric'), varargin);
  args = varargin(~sym);
  if ~any(sym), y = builtin('ifft', x, args{:}); return; end
  if ~isempty(args), error('ifft shim: the symmetric flag is supported without n and dim'); end
  d = find(size(x) ~= 1, 1); if isempty(d), d = 1; end
  perm = [d, setdiff(1:ndims(x), d)];
  xp = permute(x, perm); sz = size(xp); n = sz(1); xp = reshape(xp, n, []);
  h = floor(n / 2) + 1;
  xs = xp; xs(1, :) = real(xp(1, :));
  if mod(n, 2) == 0, xs(h, :) = real(xp(h, :)); end
  xs(h + 1:n, :) = conj(xp(n - h + 1:-1:2, :));
  y = real(builtin('ifft', xs));
  y = ipermute(reshape(y, sz), perm);
end
