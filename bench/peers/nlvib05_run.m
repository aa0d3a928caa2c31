% Driver for the NLvib side of bench/peers (squeal issue 29).
% Runs the harmonic-balance part of NLvib's
% EXAMPLES/05_twoDOFoscillator_tanhDryFriction_NM with the example's own
% parameters (written out below, unchanged), times it, and writes CSVs.
% NLvib itself is not in this repository: point NLVIB at a checkout.
%
%   NLVIB=/tmp/nlvib octave --no-gui --quiet bench/peers/nlvib05_run.m
%   (NLVIB_SHOOT=1 also runs the example's shooting continuation;
%    NLVIB_TOL=1e-12 tightens fsolve's tolerances, output *_tight.csv)
nlvib = getenv('NLVIB');
if isempty(nlvib), nlvib = '/tmp/nlvib'; end
addpath(fullfile(nlvib,'SRC'));
addpath(fullfile(nlvib,'SRC','MechanicalSystems'));
outdir = fileparts(mfilename('fullpath'));

% --- system, exactly as in the example ---
mi = [.02 1]; ki = [0 40 600]; di = 0*ki;
eps_reg = .05; muN = 5; W = [1;0];
nonlinear_elements = struct('type','tanhDryFriction',...
    'eps',eps_reg,'friction_limit_force',muN,'force_direction',W);
oscillator = ChainOfOscillators(mi,di,ki,nonlinear_elements);
n = oscillator.n; M = oscillator.M;

inl = find(W); B = eye(n); B(:,inl) = [];
[PHI_fixed,OM2] = eig(B'*oscillator.K*B,B'*oscillator.M*B);
om_fixed = sqrt(diag(OM2));
[om_fixed,ind] = sort(om_fixed); PHI_fixed = B*PHI_fixed(:,ind);
[PHI_free,OM2] = eig(oscillator.K,oscillator.M);
[om_free,ind] = sort(sqrt(diag(OM2))); PHI_free = PHI_free(:,ind);
printf('stuck mode 1: %.9f rad/s (%.9f Hz); free modes %.9f %.9f rad/s\n', ...
    om_fixed(1), om_fixed(1)/2/pi, om_free(1), om_free(2));

% --- HB nonlinear modal analysis, exactly as in the example ---
analysis = 'NMA';
H = 21; Ntd = 2^10; imod = 1;
% NLVIB_NTD overrides the AFT's time samples per period (output *_ntd<v>.csv)
ntd_env = str2double(getenv('NLVIB_NTD'));
if ~isnan(ntd_env), Ntd = ntd_env; end
% NLVIB_H overrides the harmonic order (output *_H<v>.csv)
h_env = str2double(getenv('NLVIB_H'));
if ~isnan(h_env), H = h_env; end
log10a_s = -1.5; log10a_e = 1; inorm = 2;
om = om_fixed(imod); phi = PHI_fixed(:,imod);
Psi = zeros((2*H+1)*n,1); Psi(n+(1:n)) = phi;
x0 = [Psi;om;0];
ds = .01;
% NLVIB_DS overrides the example's arclength step (a denser curve, for
% interpolation); output *_ds<value>.csv
ds_env = str2double(getenv('NLVIB_DS'));
if ~isnan(ds_env), ds = ds_env; end
% NLVIB_LOG10A='s:e' overrides the amplitude range (log10 of NLvib's a);
% the step is then capped at ds (output *_zoom.csv)
Sopt = struct();
rng = getenv('NLVIB_LOG10A');
if ~isempty(rng)
  v = str2double(strsplit(rng,':')); log10a_s = v(1); log10a_e = v(2);
  Sopt.dsmax = ds;
end
fscl = mean(abs(oscillator.K*phi));
% Octave's optimset does not take a function handle (NLvib's default
% `optimset(optimset(@fsolve),...)` fails there), so the driver passes the
% same fsolve options as NLvib's default through solve_and_continue's
% documented optional inputs (options struct, postprocessing, solver options).
Solopt = optimset(optimset('fsolve'),'Display','off','Jacobian','on','MaxIter',50);
% NLVIB_TOL=1e-12 tightens fsolve's TolFun and TolX (same NLvib code, only
% the solver's stopping rule) and writes *_tight.csv instead.
tol = str2double(getenv('NLVIB_TOL')); suffix = '';
if ~isnan(tol)
  Solopt = optimset(Solopt,'TolFun',tol,'TolX',tol); suffix = '_tight';
end
if ~isnan(ds_env), suffix = [suffix '_ds' getenv('NLVIB_DS')]; end
if ~isempty(rng), suffix = [suffix '_zoom']; end
if ~isnan(ntd_env), suffix = [suffix '_ntd' getenv('NLVIB_NTD')]; end
if ~isnan(h_env), suffix = [suffix '_H' getenv('NLVIB_H')]; end
t0 = tic;
[X_HB,Solinfo] = solve_and_continue(x0,...
    @(X) HB_residual(X,oscillator,H,Ntd,analysis,inorm,fscl),...
    log10a_s,log10a_e,ds,Sopt,{},Solopt);
t_hb = toc(t0);

Psi_HB = X_HB(1:end-3,:);
om_HB = X_HB(end-2,:); del_HB = X_HB(end-1,:);
a_HB = 10.^X_HB(end,:);
np = size(X_HB,2);
% squeal's amplitude: first harmonic only, sqrt(a1'M a1 + b1'M b1);
% NLvib's a: all harmonics (0..H), a^2 = sum_k (a_k'M a_k + b_k'M b_k).
A1 = zeros(1,np); x1c = zeros(1,np); x2c = zeros(1,np);
for j = 1:np
  c1 = Psi_HB(n+(1:n),j)*a_HB(j); s1 = Psi_HB(2*n+(1:n),j)*a_HB(j);
  A1(j) = sqrt(c1'*M*c1 + s1'*M*s1);
  x1c(j) = hypot(c1(1),s1(1)); x2c(j) = hypot(c1(2),s1(2));
end
% residual of each returned point (NLvib's scaled HB residual, its 2-norm)
res = zeros(1,np);
for j = 1:np
  res(j) = norm(HB_residual(X_HB(:,j),oscillator,H,Ntd,analysis,inorm,fscl));
end
fid = fopen(fullfile(outdir,['nlvib05_nlvib_hb' suffix '.csv']),'w');
fprintf(fid,'log10a_nlvib,a_nlvib,modal_amplitude_h1,omega_rad_s,freq_hz,damping_ratio,xi,amp_h1_x1,amp_h1_x2,residual,fsolve_exitflag\n');
for j = 1:np
  fprintf(fid,'%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.3e,%d\n', ...
    log10(a_HB(j)),a_HB(j),A1(j),om_HB(j),om_HB(j)/2/pi,del_HB(j), ...
    2*om_HB(j)*del_HB(j),x1c(j),x2c(j),res(j),Solinfo.IEx(j));
end
fclose(fid);
printf('NLVIB_HB points=%d time_s=%.3f fevals=%d\n', np, t_hb, Solinfo.FCtotal);

if strcmp(getenv('NLVIB_SHOOT'),'1')
  Ntd = 2^10;
  nnorm = setdiff(1:n,inorm);
  phi = PHI_free(:,imod);
  qs = phi/phi(inorm); us = 0*phi;
  x0 = [qs(nnorm);us(nnorm);om_fixed(imod);0];
  qscl = max(abs(qs(nnorm)));
  t0 = tic;
  X_shoot = solve_and_continue(x0,...
      @(X) shooting_residual(X,oscillator,Ntd,1,analysis,qscl,[],inorm),...
      -1.5,1,.02,struct(),{},Solopt);
  t_sh = toc(t0);
  % first-harmonic mass-normalised amplitude of each shooting orbit
  ns = size(X_shoot,2); A1s = zeros(1,ns);
  for j = 1:ns
    [~,~,~,Y] = shooting_residual(X_shoot(:,j),oscillator,Ntd,1,analysis,qscl,[],inorm);
    q = Y(:,1:n); tau = (0:Ntd-1)'*2*pi/Ntd;
    c1 = 2/Ntd*(q'*cos(tau)); s1 = 2/Ntd*(q'*sin(tau));
    A1s(j) = sqrt(c1'*M*c1 + s1'*M*s1);
  end
  fid = fopen(fullfile(outdir,['nlvib05_nlvib_shoot' suffix '.csv']),'w');
  fprintf(fid,'log10qs_inorm,modal_amplitude_h1,omega_rad_s,freq_hz,damping_ratio\n');
  for j = 1:ns
    fprintf(fid,'%.12g,%.12g,%.12g,%.12g,%.12g\n', X_shoot(end,j), A1s(j), ...
      X_shoot(end-2,j), X_shoot(end-2,j)/2/pi, X_shoot(end-1,j));
  end
  fclose(fid);
  printf('NLVIB_SHOOT points=%d time_s=%.3f\n', ns, t_sh);
end
