!> The `vissim` method (docs/method.md section 7): an imitation of the tutorial's block diagram,
!> kept so that the speed/accuracy trade against the event method can be measured on the
!> same scenes. Fixed-step RK4 with no event location; collisions are seen as sign changes
!> of a gap at step ends and applied with the velocities of the step before (the diagram's
!> one-step delay); walls are limited integrators (positions clamped); friction follows the
!> diagram's rules with a zero-velocity threshold (static friction's bound when at rest).
!> Springs and dampers add their forces to the applied ones. Its errors are O(dt) by design.
!> Any number of bodies, on N-long arrays and the rows' ends.
module impact1d_vissim
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, sample_time
  use impact1d_output, only: sink_type, run_stats, emit_bodies, class_impact, checkpoint
  use impact1d_event_log, only: log_event
  use impact1d_elements, only: element_potential, element_damping_power
  use impact1d_nbody_step, only: nbody_force
  implicit none
  private
  public :: run_vissim

  !> A step that would leave less than this many dt before a sample time goes to the sample.
  real(wp), parameter :: sample_snap = 1.0e-9_wp

contains

  !> Run a scene by the tutorial's scheme from t = 0 to t_end, every dt_out sample and every
  !> impact to sink, on N-long arrays and the rows' ends (docs/method.md section 7). Each step
  !> is RK4 on x' = thr(v), v' = (f + friction) / m; a row whose gap went from >= 0 to < 0 over
  !> the step takes Newton's impulse on its two ends from their velocities before the step
  !> (rows between bodies first, in row order, then the walls, which clamp their body's
  !> position); after a collision every body's velocity before is its velocity now, for any
  !> later row of the same step. Memory allocated once: nothing per step.
  subroutine run_vissim(scene, sink, stats, error)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats   !< fresh from run (its interrupt epoch set)
    type(error_type), allocatable, intent(out) :: error
    real(wp), allocatable, dimension(:) :: x, v, v_prev, x_new, v_new, v_out, v_hit, zero, gap_before, f, fr, &
      f_ext, vs, dx
    real(wp), allocatable :: kx(:, :), kv(:, :)
    integer, allocatable :: order(:)
    real(wp) :: t, h, t_sample, work, friction_loss, impact_loss, damping_loss, ke0, pe0
    integer :: n, j_sample, k, n_order

    n = scene%n_bodies
    allocate(x(n), v(n), v_prev(n), x_new(n), v_new(n), v_out(n), v_hit(n), zero(n), f(n), fr(n), f_ext(n), vs(n), &
      dx(n), kx(n, 4), kv(n, 4), gap_before(scene%n_rows), order(scene%n_rows))
    call collision_order(scene, order, n_order)
    t = 0.0_wp
    x = scene%body_x0
    v = scene%body_v0
    zero = 0.0_wp
    work = 0.0_wp
    friction_loss = 0.0_wp
    impact_loss = 0.0_wp
    damping_loss = 0.0_wp
    v_out = zero_below(v, scene%zero_velocity)
    ke0 = 0.5_wp * dot_product(scene%body_mass, v_out**2)
    pe0 = 0.0_wp
    if (scene%springs%present) pe0 = element_potential(scene, x, zero)
    j_sample = 0
    call emit()
    if (allocated(error)) return
    do while (j_sample < scene%n_samples)
      t_sample = sample_time(scene, j_sample)
      h = step_toward(scene, t, t_sample)
      v_prev = v
      do k = 1, scene%n_rows
        gap_before(k) = gap(k)
      end do
      call rk4()
      t = t + h
      if (t_sample - t <= sample_snap * scene%dt) t = t_sample
      x = x_new
      v = v_new
      call count_step(scene, sink, stats, t, error)
      if (allocated(error)) return
      if (.not. (all(abs(x) <= huge(1.0_wp)) .and. all(abs(v) <= huge(1.0_wp)))) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': the state is no longer finite')
        return
      end if
      do k = 1, n_order
        if (gap_before(order(k)) >= 0.0_wp .and. gap(order(k)) < 0.0_wp) call collide(order(k))
      end do
      if (t == t_sample) then
        call emit()
        if (allocated(error)) return
      end if
    end do
    call sink%end_progress()

  contains

    subroutine emit()
      real(wp) :: pe
      pe = 0.0_wp
      if (scene%springs%present) pe = element_potential(scene, x, zero)
      v_out = zero_below(v, scene%zero_velocity)
      call emit_bodies(sink, stats, t, x, v_out, scene%body_mass, ke0, work, friction_loss, impact_loss, &
        scene%springs%present, [pe, pe0, damping_loss], error)
      j_sample = j_sample + 1
    end subroutine emit

    !> Row k's gap at the positions x (its normal on the ends, 0 for the ground).
    pure real(wp) function gap(k)
      integer, intent(in) :: k
      gap = scene%row_normal(2, k) * x(scene%row_body(2, k)) + scene%row_offset(k)
      if (scene%row_body(1, k) > 0) gap = gap + scene%row_normal(1, k) * x(scene%row_body(1, k))
    end function gap

    !> Row c crossed in the last step: a wall clamps its body onto the limit; Newton's impulse
    !> with the row's restitution on the ends' thresholded velocities before the step. The
    !> log takes every body's thresholded velocities at the hit and after (log_event reports
    !> the row's ends from them, or with one or two bodies the bodies, as the tutorial's log).
    subroutine collide(c)
      integer, intent(in) :: c
      real(wp) :: before(2), after(2), hit(2), n_end(2), m(2), u, p
      integer :: ends(2), e
      ends = scene%row_body(:, c)
      n_end = scene%row_normal(:, c)
      before = 0.0_wp
      hit = 0.0_wp
      m = 1.0_wp
      do e = 1, 2
        if (ends(e) == 0) then
          n_end(e) = 0.0_wp
          cycle
        end if
        before(e) = zero_below(v_prev(ends(e)), scene%zero_velocity)
        hit(e) = zero_below(v(ends(e)), scene%zero_velocity)
        m(e) = scene%body_mass(ends(e))
      end do
      v_hit = zero_below(v, scene%zero_velocity)
      if (ends(1) == 0) x(ends(2)) = -scene%row_offset(c) / scene%row_normal(2, c)
      u = dot_product(n_end, before)
      p = -(1.0_wp + scene%row_restitution(c)) * u / dot_product(n_end**2, 1.0_wp / m)
      after = before + n_end * p / m
      do e = 1, 2
        if (ends(e) == 0) cycle
        v(ends(e)) = after(e)
        after(e) = zero_below(after(e), scene%zero_velocity)
        impact_loss = impact_loss + 0.5_wp * m(e) * (hit(e)**2 - after(e)**2)
      end do
      v_prev = v     ! (O(N) a collision: the diagram's rule, which later rows of the step see)
      v_out = zero_below(v, scene%zero_velocity)
      call log_event(scene, sink, stats, t, class_impact, c, v_hit, v_out)
    end subroutine collide

    !> One classical RK4 step of length h from (t, x, v) to (x_new, v_new), the work, friction
    !> and damping dissipation integrated by the same stages (the work is the external forces'
    !> only: f holds the springs' and dampers' too).
    subroutine rk4()
      real(wp) :: kw(4), kd(4), kc(4), ts
      integer :: stage
      real(wp), parameter :: c(4) = [0.0_wp, 0.5_wp, 0.5_wp, 1.0_wp]
      kc = 0.0_wp
      do stage = 1, 4
        ts = t + c(stage) * h
        vs = v
        dx = 0.0_wp
        if (stage > 1) then
          vs = v + c(stage) * h * kv(:, stage - 1)
          dx = c(stage) * h * kx(:, stage - 1)
        end if
        vs = zero_below(vs, scene%zero_velocity)
        call scene%forcing%force_all(ts, f_ext)
        f = f_ext
        if (scene%springs%present) then
          ! The elements' pulls summed from +0, then added to the external forces: the order
          ! the tutorial's scenes were first run in (tests/golden), which adding each pull
          ! to f in turn would round otherwise.
          call nbody_force(scene, ts, x, dx, vs, f, external=zero)
          f = f_ext + f
        end if
        fr = friction_block(vs, f, scene%body_friction, scene%body_static, scene%zero_velocity)
        kx(:, stage) = vs
        kv(:, stage) = (f + fr) / scene%body_mass
        kw(stage) = dot_product(f_ext, vs)
        kd(stage) = -dot_product(fr, vs)
        if (scene%springs%present) kc(stage) = element_damping_power(scene, vs)
      end do
      x_new = x + h / 6.0_wp * (((kx(:, 1) + 2.0_wp * kx(:, 2)) + 2.0_wp * kx(:, 3)) + kx(:, 4))
      v_new = v + h / 6.0_wp * (((kv(:, 1) + 2.0_wp * kv(:, 2)) + 2.0_wp * kv(:, 3)) + kv(:, 4))
      work = work + h / 6.0_wp * (((kw(1) + 2.0_wp * kw(2)) + 2.0_wp * kw(3)) + kw(4))
      friction_loss = friction_loss + h / 6.0_wp * (((kd(1) + 2.0_wp * kd(2)) + 2.0_wp * kd(3)) + kd(4))
      damping_loss = damping_loss + h / 6.0_wp * (((kc(1) + 2.0_wp * kc(2)) + 2.0_wp * kc(3)) + kc(4))
    end subroutine rk4
  end subroutine run_vissim

  !> A step taken at t: counted, and every 4096th a checkpoint (progress, Ctrl-C).
  subroutine count_step(scene, sink, stats, t, error)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp), intent(in) :: t
    type(error_type), allocatable, intent(inout) :: error
    stats%steps = stats%steps + 1
    if (iand(stats%steps, 4095_int64) == 0) call checkpoint(sink, stats, t, scene%t_end, error)
  end subroutine count_step

  !> The order in which a step's collisions are taken: rows between bodies first, then the
  !> ground rows on what they left (the tutorial's slot, then its walls), each in row order.
  pure subroutine collision_order(scene, order, n_order)
    type(scene_type), intent(in) :: scene
    integer, intent(out) :: order(:), n_order
    integer :: k
    n_order = 0
    do k = 1, scene%n_rows
      if (scene%row_body(1, k) == 0) cycle
      n_order = n_order + 1
      order(n_order) = k
    end do
    do k = 1, scene%n_rows
      if (scene%row_body(1, k) /= 0) cycle
      n_order = n_order + 1
      order(n_order) = k
    end do
  end subroutine collision_order

  !> The next step from t toward the sample time t_sample: dt, or what is left when that is
  !> less than a step (or a step and a sliver).
  pure real(wp) function step_toward(scene, t, t_sample) result(h)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, t_sample
    h = min(scene%dt, t_sample - t)
    if (t_sample - t - h <= sample_snap * scene%dt) h = t_sample - t
  end function step_toward

  !> The diagram's "no movement on zero velocity": |v| <= zero_velocity reads as zero.
  elemental real(wp) function zero_below(velocity, zero_velocity) result(thresholded)
    real(wp), intent(in) :: velocity, zero_velocity
    thresholded = merge(0.0_wp, velocity, abs(velocity) <= zero_velocity)
  end function zero_below

  !> The diagram's friction block: sliding friction (bound c) when moving, otherwise the
  !> smaller of the static bound s and the applied force f, opposing the applied force.
  elemental real(wp) function friction_block(velocity, f, c, s, zero_velocity) result(force)
    real(wp), intent(in) :: velocity, f, c, s, zero_velocity
    if (abs(velocity) > zero_velocity) then
      force = -c * sign(1.0_wp, velocity)
    else
      force = -sign(min(s, abs(f)), f)
    end if
  end function friction_block
end module impact1d_vissim
