!> Contact and friction modes: which contacts are held closed, which bodies are held by
!> static friction, and which way sliding friction acts. Within a mode the accelerations are
!> a linear function of the external forces only, a = gain (f(t) + f_slide), so the stepping
!> loop pays two multiply-adds per stage for them.
!> The solver here is a kernel for two bodies: it sees a unit of one or two bodies through a
!> pair_type (their masses, friction bounds and the rows' normals as 2-vectors). A one-body
!> unit is padded with a phantom body (unit mass, at rest, no friction, on no row) that
!> exists only here, so that one-body results stay those of the two-body solver bit for bit.
module impact1d_modes
  use impact1d_kinds, only: wp, eps_wp
  implicit none
  private
  public :: mode_type, pair_type, solve_mode, max_holds, pair_rows

  !> Conditions a mode needs (contact force >= 0, |static friction| <= bound): at most two
  !> locked rows, two conditions for a stuck body.
  integer, parameter :: max_holds = 4
  !> Rows a unit of two bodies can have: the tutorial's walls and slot (four), and room for
  !> more contact records on the pair (issue 19, stage 3). The enumeration tries subsets of
  !> the rows present only (2**n_rows masks), so the room costs nothing per event.
  integer, parameter :: pair_rows = 8

  !> What the kernel sees of a unit of n bodies (n = 1: body 2 is the phantom).
  type :: pair_type
    integer :: n = 2                                !< bodies in the unit: 1 or 2
    integer :: n_rows = 0                           !< rows on the unit (<= pair_rows): the model's rows
    real(wp) :: mass(2) = 1.0_wp                    !< (2) kg; the phantom's 1
    real(wp) :: friction(2) = 0.0_wp                !< (2) sliding friction bounds c_i, N
    real(wp) :: static_friction(2) = 0.0_wp        !< (2) static friction bounds s_i >= c_i, N
    !> (2, pair_rows) row k's coefficients on the two bodies: gap_k = normal(:, k) . x + offset_k
    real(wp) :: normal(2, pair_rows) = 0.0_wp
  end type pair_type

  !> A mode of the pair's two bodies; its forces and accelerations are over the unit's n.
  type :: mode_type
    logical :: active(pair_rows) = .false.    !< rows held closed (persistent)
    logical :: stuck(2) = .false.             !< bodies held by static friction
    real(wp) :: sgn(2) = 0.0_wp               !< sliding direction: friction is -c_i sgn_i
    real(wp) :: f_slide(2) = 0.0_wp           !< the sliding friction forces -c_i sgn_i
    real(wp) :: gain(2, 2) = 0.0_wp           !< a = gain (f + f_slide)
    integer :: n_hold = 0
    real(wp) :: hold_w(2, max_holds) = 0.0_wp !< hold_j = hold_w(:,j) . (f + f_slide) + hold_c(j) >= 0
    real(wp) :: hold_c(max_holds) = 0.0_wp
    !> The compliant stops engaged (bit j - 1: the scene's stop row n_rows + j), switched at
    !> event points (impact1d_event_point's switch_stops) and kept through the mode's solve.
    integer :: engaged = 0
  contains
    procedure :: acceleration
    procedure :: holds
  end type mode_type

contains

  !> Accelerations a of the pair's two bodies (lanes) under forces f in this mode: a = gain
  !> (f + f_slide), matmul's sums (from +0, in column order) written out, small enough to be
  !> inlined into the stepping loop (a subroutine: an array-valued function result's
  !> temporary may go to the heap).
  pure subroutine acceleration(self, f, a)
    class(mode_type), intent(in) :: self
    real(wp), intent(in) :: f(2)
    real(wp), intent(out) :: a(2)
    real(wp) :: load(2)
    load = f + self%f_slide
    a(1) = (0.0_wp + self%gain(1, 1) * load(1)) + self%gain(1, 2) * load(2)
    a(2) = (0.0_wp + self%gain(2, 1) * load(1)) + self%gain(2, 2) * load(2)
  end subroutine acceleration

  !> Values of the mode's conditions under forces f (lanes): the mode ends when one turns negative.
  pure function holds(self, f) result(h)
    class(mode_type), intent(in) :: self
    real(wp), intent(in) :: f(2)
    real(wp) :: h(max_holds)
    integer :: j
    h = 0.0_wp
    do j = 1, self%n_hold
      h(j) = dot_product(self%hold_w(:, j), f + self%f_slide) + self%hold_c(j)
    end do
  end function holds

  !> Solve the complementarity problem at one instant by enumeration (docs/method.md section 2).
  !> candidate(k): contact k is closed with zero normal velocity; resting(i): body i is at
  !> rest with friction; moving_sign(i): sign of v_i for the other bodies with friction.
  !> f and df are the forces and their right derivative at that instant: a condition that
  !> sits exactly at its bound is accepted only if it is not about to be violated.
  !> Preference: more bodies stuck, then more contacts held. Only combinations whose locked
  !> rows are independent are tried; that loses no solution (a vertex of the feasible
  !> reaction set has independent rows, the other reactions sitting at a bound).
  !> force_scale: the size of the forces around this instant (what a step can change them
  !> by included), the yardstick of rounding; without it, the forces now.
  !> f, df, resting and moving_sign are the pair's (lanes).
  subroutine solve_mode(pair, f, df, candidate, resting, moving_sign, mode, found, force_scale)
    type(pair_type), intent(in) :: pair
    real(wp), intent(in) :: f(2), df(2)
    logical, intent(in) :: candidate(pair_rows), resting(2)
    real(wp), intent(in) :: moving_sign(2)
    type(mode_type), intent(out) :: mode
    logical, intent(out) :: found
    real(wp), intent(in), optional :: force_scale
    real(wp) :: scale
    integer :: target_stuck, o1, o2, mask, n_active, target_active, k
    integer :: option(2)
    logical :: active(pair_rows)

    found = .false.
    scale = sum(abs(f)) + 2.0_wp * sum(pair%static_friction)
    if (present(force_scale)) scale = max(scale, force_scale)
    do target_stuck = 2, 0, -1
      do o1 = 0, 2
        do o2 = 0, 2
          option = [o1, o2]
          ! option 0 = stuck, 1 = sliding +, 2 = sliding -; only resting bodies have a choice.
          if ((.not. resting(1) .and. o1 /= 0) .or. (.not. resting(2) .and. o2 /= 0)) cycle
          if (count(option == 0 .and. resting) /= target_stuck) cycle
          do target_active = count(candidate), 0, -1
            do mask = 0, 2**pair%n_rows - 1
              active = [(btest(mask, k - 1), k = 1, pair_rows)]
              if (any(active .and. .not. candidate)) cycle
              n_active = count(active)
              if (n_active /= target_active) cycle
              call try_mode(pair, f, df, scale, candidate, resting, moving_sign, option, active, mode, found)
              if (found) return
            end do
          end do
        end do
      end do
    end do
  end subroutine solve_mode

  subroutine try_mode(pair, f, df, scale, candidate, resting, moving_sign, option, active, mode, found)
    type(pair_type), intent(in) :: pair
    real(wp), intent(in) :: f(2), df(2), scale, moving_sign(2)
    logical, intent(in) :: candidate(pair_rows), resting(2), active(pair_rows)
    integer, intent(in) :: option(2)
    type(mode_type), intent(inout) :: mode
    logical, intent(out) :: found
    real(wp) :: rows(2, 2), minv(2), s(2, 2), sinv(2, 2), det, k_gain(2, 2), jm(2, 2)
    real(wp) :: load(2), w(2), tol, tol_rate, meff
    integer :: m, i, k, p, row_body(2), row_contact(2)

    found = .false.
    minv = 1.0_wp / pair%mass
    mode%active = active
    mode%stuck = resting .and. option == 0
    mode%sgn = moving_sign
    do i = 1, 2
      if (resting(i) .and. option(i) == 1) mode%sgn(i) = 1.0_wp
      if (resting(i) .and. option(i) == 2) mode%sgn(i) = -1.0_wp
    end do
    mode%f_slide = -pair%friction * mode%sgn

    load = f + mode%f_slide
    tol = 1.0e3_wp * eps_wp * scale + tiny(1.0_wp)
    tol_rate = 1.0e3_wp * eps_wp * sum(abs(df))
    ! Both bodies stuck and pressed together through the link: three locked rows in two
    ! dimensions, dependent, so the contact force lambda >= 0 is not fixed by them. The
    ! mode holds while some lambda keeps both static frictions within their bounds,
    ! |f_i + lambda n_i| <= mus_i m_i g: lambda lies in two intervals centred on -n_i f_i,
    ! and eliminating it (Fourier-Motzkin) leaves four linear conditions on f. Without this
    ! the pair would hold only up to one body's sliding bound plus the other's static one.
    ! Only where the link must carry load: a rigid link or bodies merely touching log no rest.
    if (all(mode%stuck) .and. count(active) == 1) then
      k = findloc(active, .true., dim=1)
      if (all(pair%normal(:, k) /= 0.0_wp)) then
        if (admissible([-1.0_wp, 0.0_wp], pair%static_friction(1)) .and. &
            admissible([1.0_wp, 0.0_wp], pair%static_friction(1)) .and. &
            admissible([0.0_wp, -1.0_wp], pair%static_friction(2)) .and. &
            admissible([0.0_wp, 1.0_wp], pair%static_friction(2))) return
        mode%gain = 0.0_wp
        mode%n_hold = 0
        call add_hold([-pair%normal(1, k), 0.0_wp], pair%static_friction(1))
        call add_hold([0.0_wp, -pair%normal(2, k)], pair%static_friction(2))
        call add_hold([pair%normal(1, k), -pair%normal(2, k)], sum(pair%static_friction))
        call add_hold([-pair%normal(1, k), pair%normal(2, k)], sum(pair%static_friction))
        found = all([(admissible(mode%hold_w(:, p), mode%hold_c(p)), p = 1, mode%n_hold)])
        return
      end if
    end if

    ! Locked rows: held contacts (normal n_k) and stuck bodies (unit row e_i).
    m = 0
    row_body = 0
    row_contact = 0
    do k = 1, pair_rows
      if (.not. active(k)) cycle
      m = m + 1
      if (m > 2) return
      rows(m, :) = pair%normal(:, k)
      row_contact(m) = k
    end do
    do i = 1, 2
      if (.not. mode%stuck(i)) cycle
      m = m + 1
      if (m > 2) return
      rows(m, :) = 0.0_wp
      rows(m, i) = 1.0_wp
      row_body(m) = i
    end do

    ! M a = f + f_slide + J^T mu, J a = 0  =>  mu = K (f + f_slide), a = M^-1 (I + J^T K) (f + f_slide).
    mode%gain = 0.0_wp
    mode%gain(1, 1) = minv(1)
    mode%gain(2, 2) = minv(2)
    k_gain = 0.0_wp
    if (m > 0) then
      do p = 1, m
        jm(p, :) = rows(p, :) * minv
      end do
      s(1:m, 1:m) = matmul(jm(1:m, :), transpose(rows(1:m, :)))
      if (m == 1) then
        sinv(1, 1) = 1.0_wp / s(1, 1)
      else
        det = s(1, 1) * s(2, 2) - s(1, 2) * s(2, 1)
        ! Dependent rows (a wall and a stuck body on the same body, both slot limits).
        if (abs(det) <= 1.0e-12_wp * s(1, 1) * s(2, 2)) return
        sinv = reshape([s(2, 2), -s(2, 1), -s(1, 2), s(1, 1)], [2, 2]) / det
      end if
      k_gain(1:m, :) = -matmul(sinv(1:m, 1:m), jm(1:m, :))
      do i = 1, 2
        mode%gain(i, :) = mode%gain(i, :) + minv(i) * matmul(rows(1:m, i), k_gain(1:m, :))
      end do
      ! Make the held motion exact, not rounding-small: a body on a wall or stuck does not
      ! creep, a closed slot moves both bodies alike.
      if (m == 2) mode%gain = 0.0_wp
      do p = 1, m
        do i = 1, 2
          if (rows(p, i) /= 0.0_wp .and. rows(p, 3 - i) == 0.0_wp) mode%gain(i, :) = 0.0_wp
        end do
        if (rows(p, 1) /= 0.0_wp .and. rows(p, 2) /= 0.0_wp) then
          mode%gain(1, :) = 0.5_wp * (mode%gain(1, :) + mode%gain(2, :))
          mode%gain(2, :) = mode%gain(1, :)
        end if
      end do
    end if

    mode%n_hold = 0
    do p = 1, m
      if (row_contact(p) > 0) then
        call add_hold(k_gain(p, :), 0.0_wp)                       ! contact force >= 0
      else
        i = row_body(p)
        call add_hold(-k_gain(p, :), pair%static_friction(i))    ! static friction <= mus_i m_i g
        call add_hold(k_gain(p, :), pair%static_friction(i))     ! static friction >= -mus_i m_i g
      end if
    end do
    do p = 1, mode%n_hold
      if (.not. admissible(mode%hold_w(:, p), mode%hold_c(p))) return
    end do
    ! A closed contact left free must not close further; a body leaving rest must move the
    ! way its friction assumes. Both are written in force units so one tolerance serves.
    do k = 1, pair_rows
      if (.not. candidate(k) .or. active(k)) cycle
      meff = 1.0_wp / dot_product(pair%normal(:, k)**2, minv)
      w = meff * matmul(pair%normal(:, k), mode%gain)
      if (.not. admissible(w, 0.0_wp)) return
    end do
    do i = 1, 2
      if (.not. resting(i) .or. mode%stuck(i)) cycle
      w = pair%mass(i) * mode%sgn(i) * mode%gain(i, :)
      if (.not. admissible(w, 0.0_wp)) return
    end do
    found = .true.

  contains

    subroutine add_hold(weights, constant)
      real(wp), intent(in) :: weights(2), constant
      mode%n_hold = mode%n_hold + 1
      mode%hold_w(:, mode%n_hold) = weights
      mode%hold_c(mode%n_hold) = constant
    end subroutine add_hold

    logical function admissible(weights, constant)
      real(wp), intent(in) :: weights(2), constant
      real(wp) :: value
      value = dot_product(weights, load) + constant
      admissible = value > tol .or. (value >= -tol .and. dot_product(weights, df) >= -tol_rate)
    end function admissible
  end subroutine try_mode
end module impact1d_modes
