!> The contacts' geometry (METHOD.md 2): gaps exact to their own size, their rounding
!> levels, and putting a closed contact exactly on its constraint.
module impact1d_contacts
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_scene, only: scene_type
  use impact1d_impacts, only: normal_velocity
  use impact1d_state, only: lane_state_type, add_compensated
  use impact1d_yardsticks, only: gap_rounding, time_rounding, velocity_rounding
  use impact1d_modes, only: mode_type, pair_rows
  use impact1d_loads, only: state_force
  use impact1d_lanes, only: max_lanes
  implicit none
  private
  public :: gap, gap_tolerance, gap_tolerance_along, displacement, snap, snap_row, rigid_pair, u_tolerance, u_tolerances
  public :: stop_gap_band, stop_force_band

contains

  !> Gap k of a state (in lanes), exact to its own size: x2 - x1 is formed without rounding
  !> (two-sum), and subtracting a limit it is close to is exact, so the slot is resolved like
  !> a wall. On the pair's normals (the mode kernel's view): the same arithmetic for one body
  !> and two, and no branch per end in the location loop.
  pure real(wp) function gap(scene, k, m)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: m
    real(wp) :: a, b, total, rounded
    a = scene%pair%normal(1, k) * m%x(1)
    b = scene%pair%normal(2, k) * m%x(2)
    total = a + b
    rounded = total - a
    gap = (total + scene%row_offset(k)) + (((a - (total - rounded)) + (b - rounded)) + &
      dot_product(scene%pair%normal(:, k), m%x_lo))
  end function gap

  !> Rounding level of gap k. A gap is exact to its own size (compensated positions, exact
  !> differences) up to the rounding of the low parts, so only that and what a step moved
  !> it by count. A gap closing within the clock's
  !> resolution is closed now: this is what makes contacts hit at the same instant one
  !> event, while a tiny flight elsewhere keeps its own time.
  pure real(wp) function gap_tolerance(scene, k, m, moved)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: m
    real(wp), intent(in) :: moved
    gap_tolerance = gap_rounding * (moved + dot_product(abs(scene%pair%normal(:, k)), abs(m%x_lo))) + &
      time_rounding * max(abs(m%t), scene%dt) * max(0.0_wp, -normal_velocity(scene, k, m%v))
  end function gap_tolerance

  !> Within how much of its limit a compliant stop row k is at it: the gap's rounding and
  !> what the rounding of the clock at an event moves it by, either way (a stop released at
  !> its limit leaves it, 1e-17 m inside, at once: open, not engaged again).
  pure real(wp) function stop_gap_band(scene, k, m) result(band)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: m
    band = gap_tolerance(scene, k, m, 0.0_wp) + &
      time_rounding * max(abs(m%t), scene%dt) * abs(normal_velocity(scene, k, m%v))
  end function stop_gap_band

  !> The rounding of a compliant stop row k's force -(k gap + c gap') in state m: what
  !> counts as zero at its engagement and release.
  pure real(wp) function stop_force_band(scene, k, m) result(band)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: m
    band = 1.0e3_wp * eps_wp * (scene%row_k(k) * max(abs(gap(scene, k, m)), stop_gap_band(scene, k, m)) + &
      scene%row_c(k) * abs(normal_velocity(scene, k, m%v))) + tiny(1.0_wp)
  end function stop_force_band

  !> gap_tolerance along a step from state a with dense output c, as a polynomial in theta:
  !> what the step has moved the gap by at theta (each body's displacement), not by the
  !> step's end, so a gap closing early in a long step is not lost in the rounding of
  !> the whole step's motion; and the gap's curvature only to the rounding of the forces
  !> (acc_rounding per body), so a contact released with a rounding-level acceleration
  !> back into it (a force ramp through its bound) does not close again at once.
  pure function gap_tolerance_along(scene, k, a, c, acc_rounding) result(q)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: c(3, max_lanes), acc_rounding(max_lanes)
    real(wp) :: q(0:3)
    q(0) = gap_tolerance(scene, k, a, 0.0_wp)
    q(1:3) = gap_rounding * (abs(scene%pair%normal(1, k)) * abs(c(:, 1)) + abs(scene%pair%normal(2, k)) * abs(c(:, 2)))
    q(2) = q(2) + 0.5_wp * dot_product(abs(scene%pair%normal(:, k)), acc_rounding)
  end function gap_tolerance_along

  !> How far a step from a to b moved gap k (through either body).
  pure real(wp) function displacement(scene, k, a, b)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: a, b
    displacement = dot_product(abs(scene%pair%normal(:, k)), abs((b%x - a%x) + (b%x_lo - a%x_lo)))
  end function displacement

  !> Put closed row k exactly on its constraint (gap = 0, no roundoff penetration): the
  !> state in lanes (snap_row on its positions).
  pure subroutine snap(scene, k, closed, s)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    logical, intent(in) :: closed(pair_rows)
    type(lane_state_type), intent(inout) :: s
    call snap_row(scene, k, closed(:scene%n_rows), s%x, s%x_lo)
  end subroutine snap

  !> Put closed row k exactly on its constraint, on positions x + x_lo (lanes or N-long: both
  !> engines). A ground row puts its body at -offset / n_b; a row between bodies puts
  !> x_b - x_a on its limit by moving the end that no closed ground row holds (b if neither
  !> is held).
  pure subroutine snap_row(scene, k, closed, x, x_lo)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    logical, intent(in) :: closed(:)
    real(wp), intent(inout) :: x(:), x_lo(:)
    real(wp) :: limit
    integer :: j
    associate (a => scene%row_body(1, k), b => scene%row_body(2, k))
      if (a == 0) then
        x(b) = -scene%row_offset(k) / scene%row_normal(2, k)
        x_lo(b) = 0.0_wp
        return
      end if
      ! x_b = x_a + d exactly, the sum's rounding kept in the low part (d = -offset / n_b:
      ! d_min for a lower limit, d_max for an upper one).
      limit = -scene%row_offset(k) / scene%row_normal(2, k)
      do j = 1, scene%n_rows
        if (closed(j) .and. scene%row_body(1, j) == 0 .and. scene%row_body(2, j) == b) then
          x(a) = x(b)
          x_lo(a) = x_lo(b)
          call add_compensated(x(a), x_lo(a), -limit)
          return
        end if
      end do
      x(b) = x(a)
      x_lo(b) = x_lo(a)
      call add_compensated(x(b), x_lo(b), limit)
    end associate
  end subroutine snap_row

  !> Both limits of a link closed (a rigid link, d_min = d_max, whose row_partner the event
  !> point closed with its row): its bodies are one. A record's two rows are adjacent, so
  !> one look at each neighbouring pair is what both_limits_closed over every row found
  !> (called several times an event: one pass, no inner loop).
  pure logical function rigid_pair(scene, closed)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(pair_rows)
    integer :: k
    rigid_pair = .false.
    do k = 1, scene%n_rows - 1
      if (closed(k) .and. closed(k + 1)) then
        if (scene%row_contact(k) == scene%row_contact(k + 1)) rigid_pair = .true.
      end if
    end do
  end function rigid_pair

  !> Rounding level of contact k's normal velocity: from the speeds of the bodies it
  !> involves and what a step changes them by, so a slow body is not judged by a fast one;
  !> within an event point, not below the speeds it started from (entry_scale, else 0).
  pure real(wp) function u_tolerance(scene, mode, s, k, entry_scale)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s
    integer, intent(in) :: k
    real(wp), intent(in) :: entry_scale(max_lanes)
    real(wp) :: f(max_lanes), acc(max_lanes)
    call state_force(scene, s, f, mode%engaged)
    call mode%acceleration(f, acc)
    u_tolerance = velocity_rounding * dot_product(abs(scene%pair%normal(:, k)), &
      max(abs(s%v) + abs(acc) * scene%dt, entry_scale))
  end function u_tolerance

  !> u_tolerance of every contact (the accelerations worked out once).
  pure function u_tolerances(scene, mode, s, entry_scale) result(tol)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: entry_scale(max_lanes)
    real(wp) :: tol(pair_rows), f(max_lanes), acc(max_lanes), speed(max_lanes)
    integer :: k
    call state_force(scene, s, f, mode%engaged)
    call mode%acceleration(f, acc)
    speed = max(abs(s%v) + abs(acc) * scene%dt, entry_scale)
    tol = 0.0_wp
    do k = 1, scene%n_rows
      tol(k) = velocity_rounding * dot_product(abs(scene%pair%normal(:, k)), speed)
    end do
  end function u_tolerances
end module impact1d_contacts
