function out = imresize(im, sz, varargin)
% IMRESIZE  MATLAB's imresize (Image Processing Toolbox) for GNU Octave, as the authors' code
% calls it: imresize(im, [rows cols] or scale [, method] [, 'Antialiasing', tf]).
% Methods 'nearest' ('box'), 'bilinear' ('triangle'), 'bicubic' ('cubic', the default).
%
% Octave's image package has its own imresize, which differs from MATLAB's in the last digits:
% it does not normalise the antialiasing weights, resizes the columns first and computes integer
% images in single precision. This one follows MATLAB's documented algorithm: per dimension, the
% output sample x maps to u = x/scale + (1 - 1/scale)/2; the kernel (cubic a = -0.5, triangle or
% box) is stretched by 1/scale when shrinking with antialiasing; the weights of each output
% sample are normalised to sum 1; indices beyond the border mirror; the dimension with the
% smaller scale goes first; each pass sums in double, in kernel-tap order, and returns the input's
% class (integers rounded and saturated), as imresizemex does.
  method = 'bicubic'; aa = [];
  k = 1;
  if k <= numel(varargin) && ischar(varargin{k}) && ~strcmpi(varargin{k}, 'antialiasing') ...
      && ~strcmpi(varargin{k}, 'method')
    method = varargin{k}; k = k + 1;
  end
  for j = k:2:numel(varargin)
    switch lower(varargin{j})
      case 'antialiasing', aa = logical(varargin{j + 1});
      case 'method', method = varargin{j + 1};
      otherwise, error('imresize shim: unsupported option %s', varargin{j});
    end
  end
  switch lower(method)
    case {'nearest', 'box'}, kernel = @box_kernel; width = 1; if isempty(aa), aa = false; end
    case {'bilinear', 'triangle'}, kernel = @triangle_kernel; width = 2;
    case {'bicubic', 'cubic'}, kernel = @cubic_kernel; width = 4;
    otherwise, error('imresize shim: unsupported method %s', method);
  end
  if isempty(aa), aa = true; end
  in_sz = [size(im, 1), size(im, 2)];
  if isscalar(sz)
    scale = [sz sz]; out_sz = ceil(sz * in_sz);
  else
    out_sz = sz(1:2);
    if isnan(out_sz(1)), out_sz(1) = ceil(out_sz(2) * in_sz(1) / in_sz(2)); end
    if isnan(out_sz(2)), out_sz(2) = ceil(out_sz(1) * in_sz(2) / in_sz(1)); end
    scale = out_sz ./ in_sz;
  end
  if scale(1) <= scale(2), order = [1 2]; else, order = [2 1]; end
  out = im;
  for d = order
    [w, ind] = contributions(in_sz(d), out_sz(d), scale(d), kernel, width, aa);
    out = resize_along(out, d, w, ind);
  end
end

function [w, ind] = contributions(in_len, out_len, scale, kernel, width, aa)
  if scale < 1 && aa
    h = @(x) scale * kernel(scale * x); width = width / scale;
  else
    h = kernel;
  end
  x = (1:out_len)';
  u = x / scale + 0.5 * (1 - 1 / scale);
  left = floor(u - width / 2);
  ind = bsxfun(@plus, left, 0:(ceil(width) + 1));
  w = h(bsxfun(@minus, u, ind));
  w = bsxfun(@rdivide, w, sum(w, 2));
  mirror = [1:in_len, in_len:-1:1];
  ind = mirror(mod(ind - 1, numel(mirror)) + 1);
  keep = any(w, 1);
  w = w(:, keep); ind = ind(:, keep);
end

function out = resize_along(im, d, w, ind)
  cls = class(im);
  if d == 2, im = permute(im, [2 1 3:ndims(im)]); end
  sz = size(im); a = reshape(double(im), sz(1), []);
  acc = zeros(size(w, 1), size(a, 2));
  for j = 1:size(w, 2)
    acc = acc + bsxfun(@times, w(:, j), a(ind(:, j), :));
  end
  sz(1) = size(w, 1);
  if isinteger(im) || islogical(im)
    acc = round(acc);
    if islogical(im), acc = acc > 0; end
  end
  out = cast(reshape(acc, sz), cls);
  if d == 2, out = permute(out, [2 1 3:ndims(out)]); end
end

function f = cubic_kernel(x)
  ax = abs(x);
  f = (1.5 * ax.^3 - 2.5 * ax.^2 + 1) .* (ax <= 1) ...
      + (-0.5 * ax.^3 + 2.5 * ax.^2 - 4 * ax + 2) .* ((1 < ax) & (ax <= 2));
end

function f = triangle_kernel(x)
  f = (x + 1) .* ((-1 <= x) & (x < 0)) + (1 - x) .* ((0 <= x) & (x <= 1));
end

function f = box_kernel(x)
  f = double((-0.5 <= x) & (x < 0.5));
end
